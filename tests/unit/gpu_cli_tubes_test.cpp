// `fibscope render --tubes` as a user meets it: listed fibers drawn as
// ray-cast tubes over the lines (the image changes where they are, and the
// summary says what was built), and one-line errors with exit code 2 for a
// bad selection or radius. Validation layers on. Skipped without a Vulkan
// device.
#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "app/tube_options.h"
#include "core/error.h"
#include "test_support.h"

namespace fibscope {
namespace {

test::CommandResult runFibscope(const std::string& args) {
  return test::runCommand(std::string(FIBSCOPE_EXE) + " " + args);
}

TEST(TubeCli, fiberSelectionsParseListsRangesAndAll) {
  EXPECT_EQ(parseFiberSelection("all", 3), (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(parseFiberSelection("4,0-2,1", 10), (std::vector<uint32_t>{4, 0, 1, 2}));
  for (const char* bad : {"", "1-", "-3", "5-2", "1,,2", "x", "2 ", "10"})
    EXPECT_THROW(parseFiberSelection(bad, 10), Error) << bad;
}

class GpuCliTubes : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::TempDir dir_;
};

TEST_F(GpuCliTubes, renderDrawsTheListedFibersAsTubesOverTheLines) {
  const std::string common = "render --validate --phantom-streamlines 200 --size 160x120 --view axial --no-ssao -o ";
  const std::string lines = dir_.file("lines.png"), tubes = dir_.file("tubes.png");
  const auto a = runFibscope(common + lines);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const auto b = runFibscope(common + tubes + " --tubes 0-9,50 --tube-radius 1.5");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_NE(b.output.find("tubes: 11 fibers"), std::string::npos) << b.output;
  const test::Png pa = test::readOurPng(lines), pb = test::readOurPng(tubes);
  ASSERT_EQ(pa.rgba.size(), pb.rgba.size());
  size_t changed = 0;
  for (size_t i = 0; i < pa.rgba.size(); i += 4)
    changed += pa.rgba[i] != pb.rgba[i] || pa.rgba[i + 1] != pb.rgba[i + 1] || pa.rgba[i + 2] != pb.rgba[i + 2];
  // Eleven tubes 3 mm wide at ~0.7 px/mm, partly behind the lines (189
  // pixels changed at radius 0.8 mm).
  EXPECT_GT(changed, 250u) << changed;
  // --tubes-dim-rest makes them the selection: every other line dims too.
  const std::string dimmed = dir_.file("dimmed.png");
  const auto c = runFibscope(common + dimmed + " --tubes 0-9,50 --tube-radius 1.5 --tubes-dim-rest");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const test::Png pc = test::readOurPng(dimmed);
  ASSERT_EQ(pc.rgba.size(), pa.rgba.size());
  size_t changed_dimmed = 0;
  for (size_t i = 0; i < pa.rgba.size(); i += 4)
    changed_dimmed += pa.rgba[i] != pc.rgba[i] || pa.rgba[i + 1] != pc.rgba[i + 1] || pa.rgba[i + 2] != pc.rgba[i + 2];
  EXPECT_GT(changed_dimmed, 3 * changed);
}

TEST_F(GpuCliTubes, filteredTubesAreTheFibersTheFilterKeeps) {
  const auto r = runFibscope(
      "render --validate --phantom-streamlines 300 --size 96x72 --include sphere:0,0,20,15 "
      "--tubes filtered --tube-radius 0.3 -o " +
      dir_.file("f.png"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  unsigned long long tubes = 0, kept = 0, total = 0;
  const size_t t = r.output.find("tubes: "), f = r.output.find("filter: ");
  ASSERT_NE(t, std::string::npos) << r.output;
  ASSERT_NE(f, std::string::npos) << r.output;
  ASSERT_EQ(std::sscanf(r.output.c_str() + t, "tubes: %llu fibers", &tubes), 1) << r.output;
  ASSERT_EQ(std::sscanf(r.output.c_str() + f, "filter: %llu of %llu", &kept, &total), 2) << r.output;
  EXPECT_EQ(tubes, kept);
  EXPECT_GT(kept, 0u);
  EXPECT_LT(kept, total);
  // Without criteria there is nothing to take.
  const auto none =
      runFibscope("render --phantom-streamlines 50 --size 64x48 --tubes filtered -o " + dir_.file("n.png"));
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_NE(none.output.find("--tubes filtered"), std::string::npos) << none.output;
}

// bench --tubes --tube-compare: every method on the same frames, their
// tube passes timed per variant, "none" the same frames without tubes.
TEST_F(GpuCliTubes, benchDrawsEachTubeMethodOnTheSameFrames) {
  const auto r = runFibscope(
      "bench --validate --phantom-streamlines 60 --size 80x60 --frames 2 --warmup 0 --tubes 0-9 --tube-radius 0.8 "
      "--tube-compare none,compute,raycast,tess --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output.substr(r.output.find('{')));
  EXPECT_EQ(j["tubes"]["fibers"], 10);
  EXPECT_GT(j["tubes"]["segments"].get<uint64_t>(), 10u);
  EXPECT_EQ(j["tubes"]["buffer_bytes"].get<uint64_t>(),
            48 * j["tubes"]["nodes"].get<uint64_t>() + 16 * j["tubes"]["segments"].get<uint64_t>());
  ASSERT_EQ(j["results"].size(), 4u);
  EXPECT_FALSE(j["results"][0].contains("tube_method"));
  EXPECT_EQ(j["results"][1]["tube_method"], "compute");
  EXPECT_EQ(j["results"][2]["tube_method"], "raycast");
  EXPECT_TRUE(j["results"][1]["pass_mean_ms"].contains("tube raycast")) << j["results"][1].dump();
  EXPECT_TRUE(j["results"][2]["pass_mean_ms"].contains("tube boxes")) << j["results"][2].dump();
  EXPECT_EQ(j["results"][3]["tube_method"], "tess");
  EXPECT_TRUE(j["results"][3]["pass_mean_ms"].contains("tube tess")) << j["results"][3].dump();
  EXPECT_GT(j["results"][3]["tube_method_bytes"].get<uint64_t>(), 0u);
  EXPECT_FALSE(j["results"][0]["pass_mean_ms"].contains("tube raycast"));
  for (const auto& [args, want] : std::vector<std::pair<std::string, std::string>>{
           {" --tube-compare compute", "--tube-compare"}, {" --tubes 0-3 --tube-compare compute,cubes", "cubes"}}) {
    const auto bad = runFibscope("bench --phantom-streamlines 40 --size 32x24 --frames 1" + args);
    EXPECT_EQ(bad.exit_code, 2) << args << ": " << bad.output;
    EXPECT_NE(bad.output.find(want), std::string::npos) << args << ": " << bad.output;
  }
}

TEST_F(GpuCliTubes, badTubeOptionsAreOneLineErrors) {
  const std::string common = "render --phantom-streamlines 50 --size 64x48 -o " + dir_.file("x.png");
  for (const auto& [args, want] : std::vector<std::pair<std::string, std::string>>{
           {" --tubes 5-2", "reversed"},
           {" --tubes 0-3 --tube-radius 0", "--tube-radius"},
           {" --tubes 0-3 --tube-radius nan", "--tube-radius"},
           {" --tubes 50", "out of range"},
           {" --tubes seven", "--tubes"},
           {" --tubes ''", "empty"},
           {" --tubes 0-3 --tube-radius 5000", "larger than the selected fibers' extent"}}) {
    const auto r = runFibscope(common + args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.output;
    EXPECT_NE(r.output.find(want), std::string::npos) << args << ": " << r.output;
  }
}

}  // namespace
}  // namespace fibscope
