// `fibscope render` and `fibscope bench` as a user meets them: a PNG of the
// built-in phantom or of a file, a JSON benchmark, one-line errors with exit
// code 2 for bad options and malformed input (and no PNG left behind).
// Validation layers on (--validate: any message is an error). Skipped
// without a Vulkan device.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// Width and height from a PNG's IHDR, or 0 x 0 when the file is no PNG.
std::pair<uint32_t, uint32_t> pngSize(const std::string& path) {
  const std::string bytes = test::readBytes(path);
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || bytes.compare(12, 4, "IHDR") != 0)
    return {0, 0};
  auto be32 = [&](size_t at) {
    return uint32_t(uint8_t(bytes[at])) << 24 | uint32_t(uint8_t(bytes[at + 1])) << 16 |
           uint32_t(uint8_t(bytes[at + 2])) << 8 | uint32_t(uint8_t(bytes[at + 3]));
  };
  return {be32(16), be32(20)};
}

// Runs fibscope as a user would. Under ASan, LeakSanitizer checks the child
// too: fibscope keeps the Vulkan driver and layers mapped until exit in
// that build (gpu/leak_check_pins.h), so their per-process allocations stay
// reachable and a real leak of theirs names its module, which
// tests/lsan_suppressions.txt (inherited from ctest's environment) can name.
test::CommandResult runGpuFibscope(const std::string& args) {
  return test::runCommand(std::string(FIBSCOPE_EXE) + " " + args);
}

class GpuCliRender : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = runGpuFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::TempDir dir_;
};

TEST_F(GpuCliRender, renderWithoutFileDrawsThePhantomToAPng) {
  const std::string png = dir_.file("phantom.png");
  const auto r = runGpuFibscope("render --validate --phantom-streamlines 300 --size 160x120 --view axial -o " + png);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(pngSize(png), std::make_pair(160u, 120u));
  EXPECT_NE(r.output.find("phantom: 300 streamlines"), std::string::npos) << r.output;
}

TEST_F(GpuCliRender, renderReadsAFileWithEveryColourAndCamera) {
  const std::string tck = dir_.file("in.tck");
  writeTractogram(tck, test::smallTractogram(50, 3), TractogramHeader{});
  for (const std::string options : {"--color solid --lighting none --no-ssao", "--color fiber --camera 10,30,0.8",
                                    "--culling none --line-width 3 --background 1,1,1", "--culling frustum",
                                    "--pipeline lines", "--pipeline raw-compute --view coronal"}) {
    SCOPED_TRACE(options);
    const std::string png = dir_.file("out.png");
    const auto r = runGpuFibscope("render --validate --size 96x64 " + options + " " + tck + " -o " + png);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(pngSize(png), std::make_pair(96u, 64u));
  }
}

// The box of the pixels that are not the background (black): x0, y0, x1, y1.
std::array<uint32_t, 4> litBox(const test::Png& png) {
  std::array<uint32_t, 4> box = {png.width, png.height, 0, 0};
  for (uint32_t y = 0; y < png.height; ++y)
    for (uint32_t x = 0; x < png.width; ++x) {
      const uint8_t* p = png.at(x, y);
      if (p[0] + p[1] + p[2] == 0) continue;
      box = {std::min(box[0], x), std::min(box[1], y), std::max(box[2], x + 1), std::max(box[3], y + 1)};
    }
  return box;
}

TEST_F(GpuCliRender, everyPipelineFramesTheSamePictureOfAFile) {
  // The compute pipeline streams the file, the baselines read it whole:
  // both frame the view from the same sample of its points (PointSample).
  const std::string tck = dir_.file("in.tck");
  ASSERT_EQ(test::runFibscope("phantom " + tck + " -n 400 --seed 4").exit_code, 0);
  std::vector<std::array<uint32_t, 4>> boxes;
  for (const std::string pipeline : {"compute", "raw-compute"}) {
    const std::string png = dir_.file(pipeline + ".png");
    const auto r = runGpuFibscope("render --validate --size 640x480 --view coronal --no-ssao --no-orientation-labels "
                                  "--pipeline " + pipeline +
                                  " " + tck + " -o " + png);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    boxes.push_back(litBox(test::readOurPng(png)));
  }
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(double(boxes[0][k]), double(boxes[1][k]), 1.0) << "edge " << k;
}

// Pixels lit (not the background) in a PNG of ours.
std::vector<uint8_t> litMask(const test::Png& png) {
  std::vector<uint8_t> lit(size_t(png.width) * png.height);
  for (uint32_t y = 0; y < png.height; ++y)
    for (uint32_t x = 0; x < png.width; ++x) {
      const uint8_t* p = png.at(x, y);
      lit[size_t(y) * png.width + x] = (p[0] | p[1] | p[2]) != 0;
    }
  return lit;
}

uint64_t keptCount(const std::string& output, const char* prefix) {
  const size_t at = output.find(prefix);
  return at == std::string::npos ? UINT64_MAX : std::stoull(output.substr(at + std::string(prefix).size()));
}

TEST_F(GpuCliRender, criteriaHideOrDimTheDroppedFibersAndKeepWhatTheFilterCommandKeeps) {
  const std::string tck = dir_.file("in.tck");
  ASSERT_EQ(test::runFibscope("phantom " + tck + " -n 400 --seed 4").exit_code, 0);
  const std::string criteria = " --include box:-60,-60,30,60,60,60 --exclude sphere:0,0,10,12 --min-length 30";
  const std::string common =
      "render --validate --size 320x240 --view coronal --no-ssao --no-orientation-labels --background 0,0,0 ";
  std::vector<std::vector<uint8_t>> lit;
  std::vector<uint64_t> kept;
  for (const std::string& extra : std::vector<std::string>{"", criteria, criteria + " --dim-dropped", criteria + " --pipeline raw-compute",
                                  criteria + " --pipeline lines"}) {
    SCOPED_TRACE(extra);
    std::string name = std::to_string(lit.size());
    name += ".png";
    const std::string png = dir_.file(name);
    const auto r = runGpuFibscope(common + tck + extra + " -o " + png);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    lit.push_back(litMask(test::readOurPng(png)));
    kept.push_back(keptCount(r.output, "filter: "));
  }
  const auto f = test::runFibscope("filter " + tck + " " + dir_.file("kept.tck") + criteria);
  ASSERT_EQ(f.exit_code, 0) << f.output;
  const uint64_t cpu_kept = keptCount(f.output, "kept.tck: ");
  ASSERT_GT(cpu_kept, 10u);
  ASSERT_LT(cpu_kept, 390u);
  // The raw pipelines test the file's own points: the same count as the CPU.
  EXPECT_EQ(kept[3], cpu_kept);
  EXPECT_EQ(kept[4], cpu_kept);
  // The fiblets' decoded points lie within the codec's error of them.
  EXPECT_NEAR(double(kept[1]), double(cpu_kept), 2.0);
  size_t all = 0, hidden = 0, outside = 0, dimmed_differ = 0;
  for (size_t i = 0; i < lit[0].size(); ++i) {
    all += lit[0][i];
    hidden += lit[1][i];
    outside += lit[1][i] && !lit[0][i];
    dimmed_differ += lit[2][i] != lit[0][i];
  }
  EXPECT_LT(hidden, all * 3 / 4) << "hidden: fewer pixels lit";
  EXPECT_GT(hidden, 0u);
  EXPECT_EQ(outside, 0u) << "a kept fiber is drawn where the whole tractogram is";
  EXPECT_EQ(dimmed_differ, 0u) << "dimmed: every fiber still drawn";
}

TEST_F(GpuCliRender, anOpenCutMeshIsAWarningAndStillCuts) {
  // A box without its top face: open, so "the cut may be approximate".
  const std::string obj = dir_.file("open.obj");
  test::writeBytes(obj,
                  "v -30 -30 -30\nv 30 -30 -30\nv 30 30 -30\nv -30 30 -30\n"
                  "v -30 -30 30\nv 30 -30 30\nv 30 30 30\nv -30 30 30\n"
                  "f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
  const std::string png = dir_.file("open.png");
  const auto r = runGpuFibscope("render --validate --phantom-streamlines 200 --size 96x64 --cut-mesh " + obj +
                                ":outside --clip-plane 0,0,0,0,0,1 --slab 40 -o " + png);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("warning"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("open.obj"), std::string::npos) << r.output;
  EXPECT_EQ(pngSize(png), std::make_pair(96u, 64u));
}

TEST_F(GpuCliRender, badOptionsAreOneLineErrors) {
  const std::string png = dir_.file("x.png");
  for (const std::string options :
       {"--size 0x10", "--size 100", "--pipeline fast", "--culling some", "--color red", "--line-width 9",
        "--background 2,0,0", "--view top", "--camera 1,2", "--view axial --camera 1,2,1",
        "--include sphere:1,2", "--exclude box:0,0,0,1", "--min-length -3", "--min-length 9 --max-length 2",
        "--clip-plane 1,2,3", "--clip-plane 0,0,0,0,0,0", "--slab -2", "--cut-mesh box:0,0,0,1:inside",
        "--cut-mesh sphere:0,0,0,5", "--cut-mesh /nonexistent/cut.obj:outside", "--roi-set /nonexistent/set.json"}) {
    SCOPED_TRACE(options);
    const auto r = runGpuFibscope("render --phantom-streamlines 10 " + options + " -o " + png);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(lineCount(r.output), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(png));
  }
  const auto r = runGpuFibscope("render --phantom-streamlines 10 -o " + dir_.file("x.jpg"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(".png"), std::string::npos) << r.output;
}

TEST_F(GpuCliRender, malformedInputIsNamedAndLeavesNoPng) {
  const std::string tck = dir_.file("broken.tck");
  test::writeBytes(tck, "mrtrix tracks\ndatatype: Float32LE\nfile: . 2000\nEND\n");
  const std::string png = dir_.file("x.png");
  const auto r = runGpuFibscope("render " + tck + " -o " + png);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find(tck), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(png));
}

TEST_F(GpuCliRender, emptyTractogramIsNamedAndLeavesNoPng) {
  const std::string tck = dir_.file("empty.tck");
  writeTractogram(tck, Tractogram{}, TractogramHeader{});
  const std::string png = dir_.file("x.png");
  const auto r = runGpuFibscope("render " + tck + " -o " + png);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find(tck + ": no streamlines"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(png));
}

TEST_F(GpuCliRender, benchReportsTheOrbitAsJson) {
  const auto r = runGpuFibscope(
      "bench --validate --json --phantom-streamlines 200 --size 192x128 --frames 4 --warmup 1 "
      "--compare compute/two-phase,compute/none,lines,raw-compute");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(json["frames"], 4);
  ASSERT_EQ(json["results"].size(), 4u);
  for (const auto& result : json["results"]) {
    EXPECT_GT(result["mean_ms"].get<double>(), 0.0);
    EXPECT_GE(result["p95_ms"].get<double>(), result["median_ms"].get<double>());
    EXPECT_GT(result["segments_drawn_per_ms"].get<double>(), 0.0);
    if (result["pipeline"] == "lines") {
      EXPECT_TRUE(result["pass_mean_ms"].contains("lines")) << result.dump();
      EXPECT_FALSE(result.contains("fiblets_drawn_fraction")) << "the baselines draw no fiblets";
      continue;
    }
    if (result["pipeline"] != "raw-compute") {
      const double drawn = result["fiblets_drawn_fraction"].get<double>();
      const double lod = result["fiblets_lod_fraction"].get<double>();
      EXPECT_GT(drawn + lod, 0.0) << result.dump();
      EXPECT_LE(drawn + lod, 1.0) << result.dump();
    }
    bool raster = false;
    for (const auto& [name, ms] : result["pass_mean_ms"].items()) raster |= name.rfind("raster", 0) == 0;
    EXPECT_TRUE(raster) << result.dump();
  }
  EXPECT_EQ(json["results"][1]["fiblets_drawn_fraction"].get<double>(), 1.0) << "no culling draws every fiblet";
}

// The filter's figure (issue 14: one changed sphere re-evaluated within a
// frame): each of --filter-evaluations re-tests every criterion; the JSON's
// gpu_ms is their median, its count the CPU filter's (the fiblets' decoded
// points within the codec's error of the file's).
TEST_F(GpuCliRender, benchTimesTheFilterOverItsEvaluations) {
  const std::string tck = dir_.file("in.tck");
  ASSERT_EQ(test::runFibscope("phantom " + tck + " -n 300 --seed 5").exit_code, 0);
  const std::string criteria = " --include sphere:-20,0,10,25 --exclude sphere:0,-40,0,10";
  const auto r = runGpuFibscope("bench --validate --json --size 96x64 --frames 1 --warmup 0 " + tck +
                                " --compare compute/two-phase,raw-compute --filter-evaluations 3" + criteria);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  const auto& f = json["filter"];
  ASSERT_EQ(f["gpu_ms_each"].size(), 3u) << f.dump();
  std::vector<double> each = f["gpu_ms_each"].get<std::vector<double>>();
  std::sort(each.begin(), each.end());
  EXPECT_EQ(f["gpu_ms"].get<double>(), each[1]) << f.dump();
  EXPECT_GT(each[0], 0.0) << f.dump();
  EXPECT_GT(f["raw_gpu_ms"].get<double>(), 0.0) << "raw-compute compared: its filter is timed too";
  const auto cpu = test::runFibscope("filter " + tck + " " + dir_.file("kept.tck") + criteria);
  ASSERT_EQ(cpu.exit_code, 0) << cpu.output;
  const uint64_t cpu_kept = keptCount(cpu.output, "kept.tck: ");
  ASSERT_GT(cpu_kept, 5u);
  EXPECT_NEAR(f["kept"].get<double>(), double(cpu_kept), 2.0);
  EXPECT_NE(runGpuFibscope("bench --phantom-streamlines 20 --frames 1 --filter-evaluations 0" + criteria).exit_code,
            0);
}

// --sample measures frames spread over the orbit, each after the frame one
// step before it: two-phase culling then draws on each exactly what it
// draws on that frame of the full orbit (its previous frame is the same),
// so the sampled fractions are the full orbit's at those frames.
TEST_F(GpuCliRender, benchSampleDrawsWhatTheFullOrbitDrawsOnTheSameFrames) {
  auto fractions = [&](const std::string& extra) {
    const auto r = runGpuFibscope("bench --validate --json --phantom-streamlines 300 --size 160x96 --frames 6 "
                                  "--step 20 --warmup 1 --compare compute/two-phase " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    if (r.exit_code != 0) return std::vector<double>{};
    const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
    return json["results"][0]["fiblets_drawn_fraction_per_frame"].get<std::vector<double>>();
  };
  const std::vector<double> full = fractions(""), sampled = fractions("--sample 3");
  ASSERT_EQ(full.size(), 6u);
  ASSERT_EQ(sampled.size(), 3u);
  for (size_t j = 0; j < 3; ++j) EXPECT_EQ(sampled[j], full[2 * j]) << "sampled frame " << j;
  // Occlusion culls something on some frame, or the test shows nothing.
  EXPECT_LT(*std::min_element(full.begin(), full.end()), 1.0);
  const auto bad = runGpuFibscope("bench --phantom-streamlines 50 --frames 4 --sample 5");
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_EQ(lineCount(bad.output), 1) << bad.output;
}

TEST_F(GpuCliRender, benchCountsMissedPixelsAgainstCullingOff) {
  const auto r = runGpuFibscope(
      "bench --validate --json --phantom-streamlines 200 --size 160x120 --frames 3 --warmup 0 --step 60 "
      "--count-missed --compare compute/two-phase,compute/coverage,compute/none");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_GT(json["reference_covered_pixels"].get<uint64_t>(), 0u);
  ASSERT_EQ(json["results"].size(), 3u);
  for (const auto& result : json["results"]) {
    if (result["pipeline"] == "compute/none") {
      EXPECT_FALSE(result.contains("missed_pixels")) << "culling off is the reference";
      continue;
    }
    ASSERT_EQ(result["missed_pixels"].size(), 3u) << result.dump();
    uint64_t sum = 0;
    for (const auto& m : result["missed_pixels"]) sum += m.get<uint64_t>();
    EXPECT_EQ(result["missed_pixels_total"].get<uint64_t>(), sum);
    if (result["pipeline"] == "compute/two-phase") EXPECT_EQ(sum, 0u) << "two-phase is conservative";
    EXPECT_EQ(result["missed_pixels"][0].get<uint64_t>(), 0u) << "the first frame has no history to miss by";
  }
}

}  // namespace
}  // namespace fibscope
