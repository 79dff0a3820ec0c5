// The viewer's virtual dissection as a script drives it (issue 14, item 4):
// ROIs on one corticospinal tract of a phantom, the kept count from the GPU
// filter against a count made here from the points, the export against
// `fibscope filter` with the same regions, the saved ROI set loaded again,
// hiding against dimming, a clip plane in the frame, and a malformed set
// file that leaves the viewer and its state as they were.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"
#include "select/roi_set.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::Png;
using test::readOurPng;

const std::string kXvfb = "xvfb-run -a -s '-screen 0 640x480x24' env ";

// The child is leak-checked under ASan: see gpu_cli_render_test.cpp. No
// orientation labels: the tests read every drawn pixel as a fiber's.
test::CommandResult runViewer(const std::string& args, const std::string& cache_dir, const std::string& prefix = "") {
  return test::runCommand(prefix + "FIBSCOPE_CACHE_DIR='" + cache_dir + "' " + FIBSCOPE_EXE +
                          " view --validate --no-orientation-labels " + args);
}

std::string lines(const std::vector<std::string>& script) {
  std::string text;
  for (const std::string& line : script) text += line + "\n";
  return text;
}

// Pixels brighter than the black background.
size_t litPixels(const Png& png) {
  size_t lit = 0;
  for (uint32_t y = 0; y < png.height; ++y)
    for (uint32_t x = 0; x < png.width; ++x) {
      const uint8_t* p = png.at(x, y);
      lit += std::max({p[0], p[1], p[2]}) > 40;
    }
  return lit;
}

// The highlight colour (RenderSettings' default 1, 0.8, 0.1) under the
// lighting: any brightness, that chromaticity.
size_t highlightedPixels(const Png& png) {
  size_t n = 0;
  for (uint32_t y = 0; y < png.height; ++y)
    for (uint32_t x = 0; x < png.width; ++x) {
      const uint8_t* p = png.at(x, y);
      const double r = p[0], g = p[1], b = p[2];
      n += r > 60 && std::abs(g / r - 0.8) < 0.08 && b / r < 0.2;
    }
  return n;
}

bool sameStreamline(const Tractogram& a, size_t s, const Tractogram& b, size_t u) {
  if (a.pointsIn(s) != b.pointsIn(u)) return false;
  return std::equal(a.positions.begin() + std::ptrdiff_t(3 * a.offsets[s]),
                    a.positions.begin() + std::ptrdiff_t(3 * a.offsets[s + 1]),
                    b.positions.begin() + std::ptrdiff_t(3 * b.offsets[u]));
}

void expectSameStreamlines(const Tractogram& got, const Tractogram& want) {
  ASSERT_EQ(got.streamlineCount(), want.streamlineCount());
  for (size_t s = 0; s < want.streamlineCount(); ++s)
    EXPECT_TRUE(sameStreamline(got, s, want, s)) << "streamline " << s;
}

// A sphere ROI with the fibers it holds, counted here from the points.
struct Sphere {
  glm::dvec3 center;
  double radius = 0;
  std::string spec() const {
    char buf[96];
    std::snprintf(buf, sizeof buf, "sphere:%g,%g,%g,%g", center.x, center.y, center.z, radius);
    return buf;
  }
};

class GpuDissectionViewer : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
    // A small phantom, written with its header (step size) and kept here
    // with the bundle of each fiber: the named bundles alone, so the two
    // spheres on the corticospinal tract keep its fibers only (in the
    // whole-brain mix, projection fibers of the white matter pass them too).
    PhantomOptions options;
    applyNamedBundlesPhantomMix(options);
    options.streamlines = 300;
    options.seed = 5;
    options.threads = 1;
    auto reader = openPhantom(options);
    TractogramHeader header = reader->header();
    phantom_ = readAllStreamlines(*reader);
    ASSERT_EQ(phantom_.per_streamline.size(), 1u);
    bundle_ = phantom_.per_streamline[0].values;
    phantom_.per_streamline.clear();
    header.per_streamline.clear();
    tck_ = dir_.file("phantom.tck");
    writeTractogram(tck_, phantom_, header);
    // The left corticospinal tract's guide points in the brainstem and the
    // internal capsule (phantom_anatomy.cpp), 6 mm spheres grown until no
    // fiber comes within 50 um of a surface: the compressed fibers the GPU
    // tests (errors of a few um) and the file's decide every fiber alike.
    low_ = fitted({-11, -20, -32});
    high_ = fitted({-21, -15, 8});
  }

  // The closest approach of fiber s to a point (mm).
  double closest(size_t s, const glm::dvec3& c) const {
    double best = INFINITY;
    for (uint64_t i = phantom_.offsets[s]; i < phantom_.offsets[s + 1]; ++i) {
      const float* p = phantom_.point(i);
      best = std::min(best, glm::length(glm::dvec3(p[0], p[1], p[2]) - c));
    }
    return best;
  }
  Sphere fitted(const glm::dvec3& center) const {
    std::vector<double> nearest;
    for (size_t s = 0; s < phantom_.streamlineCount(); ++s) nearest.push_back(closest(s, center));
    for (double r = 6.0;; r += 0.25) {
      if (std::none_of(nearest.begin(), nearest.end(), [&](double d) { return std::abs(d - r) < 0.05; }))
        return Sphere{center, r};
    }
  }
  // Fibers with a point in every sphere, in file order.
  std::vector<size_t> keptBy(const std::vector<Sphere>& spheres) const {
    std::vector<size_t> kept;
    for (size_t s = 0; s < phantom_.streamlineCount(); ++s)
      if (std::all_of(spheres.begin(), spheres.end(),
                      [&](const Sphere& sp) { return closest(s, sp.center) <= sp.radius; }))
        kept.push_back(s);
    return kept;
  }

  test::TempDir dir_;
  Tractogram phantom_;
  std::vector<float> bundle_;
  std::string tck_;
  Sphere low_, high_;
};

TEST_F(GpuDissectionViewer, scriptedRoisExportWhatFibscopeFilterWritesAndTheSavedSetLoadsBack) {
  if (test::runCommand("command -v xvfb-run").exit_code != 0) GTEST_SKIP() << "xvfb-run is not installed";
  const std::vector<size_t> both = keptBy({low_, high_}), high_only = keptBy({high_});
  ASSERT_GT(both.size(), 0u);
  ASSERT_LT(both.size(), phantom_.streamlineCount());
  ASSERT_GT(high_only.size(), both.size());  // removing a ROI keeps more
  for (size_t s : both) EXPECT_EQ(bundle_[s], float(PhantomBundle::CstLeft)) << "fiber " << s << " passes both spheres";

  // `fibscope filter` with the same regions: the reference file.
  const std::string reference = dir_.file("reference.tck");
  const auto filtered = test::runFibscope("filter " + tck_ + " " + reference + " --include " + low_.spec() +
                                          " --include " + high_.spec());
  ASSERT_EQ(filtered.exit_code, 0) << filtered.output;

  const std::string script = dir_.file("dissect.txt"), set = dir_.file("set.json");
  const std::string out_tck = dir_.file("kept.tck"), out_trx = dir_.file("kept.trx");
  const std::string hide_png = dir_.file("hide.png"), dim_png = dir_.file("dim.png"), cut_png = dir_.file("cut.png");
  const std::string shown_png = dir_.file("shown.png");
  const std::string n_both = std::to_string(both.size()), n_high = std::to_string(high_only.size());
  test::writeBytes(script, lines({
                               "roi-add cst-low include " + low_.spec(),
                               "roi-add cst-high include " + high_.spec(),
                               "expect-kept " + n_both,
                               "export-kept " + out_tck,
                               "export-kept " + out_trx,
                               "roi-save " + set,
                               "wait 1",
                               "screenshot " + hide_png + " 160x120",
                               "dropped dim",
                               "wait 1",
                               "screenshot " + dim_png + " 160x120",
                               "dropped hide",
                               // Another state: one ROI gone, lengths and ends changed.
                               "roi-remove cst-low",
                               "expect-kept " + n_high,
                               "ends-only on",
                               "length 10 20",
                               "roi-load " + set,
                               "expect-kept " + n_both,
                               // Everything cut away by a plane keeping x >= 1000 mm, then back.
                               "clip-plane-add 1000,0,0,1,0,0",
                               "wait 1",
                               "screenshot " + cut_png + " 160x120",
                               "clip-plane-clear",
                               "wait 1",
                               "screenshot " + shown_png,
                               "wait 1",
                               "quit",
                           }));
  const auto r = runViewer("--size 480x320 --script " + script + " " + tck_, dir_.file("cache"), kXvfb);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("offscreen"), std::string::npos) << "no window was made: " << r.output;

  // The exports: the reference's streamlines, in its order, point for point.
  const Tractogram want = readAllStreamlines(*openTractogram(reference));
  ASSERT_EQ(want.streamlineCount(), both.size());
  for (size_t i = 0; i < both.size(); ++i) EXPECT_TRUE(sameStreamline(want, i, phantom_, both[i])) << i;
  expectSameStreamlines(readAllStreamlines(*openTractogram(out_tck)), want);
  EXPECT_EQ(test::readBytes(out_tck), test::readBytes(reference)) << "the .tck is the file `fibscope filter` writes";
  auto trx = openTractogram(out_trx);
  const TractogramHeader trx_header = trx->header();
  expectSameStreamlines(readAllStreamlines(*trx), want);
  // A group per ROI: every kept fiber entered both include spheres.
  ASSERT_EQ(trx_header.groups.size(), 2u);
  for (const Group& g : trx_header.groups) {
    EXPECT_TRUE(g.name == "cst-low" || g.name == "cst-high") << g.name;
    std::vector<uint32_t> all(both.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
    EXPECT_EQ(g.streamlines, all) << g.name;
  }

  // The saved set, as `fibscope filter --roi-set` would read it.
  const RoiSet saved = loadRoiSet(set);
  ASSERT_EQ(saved.rois.size(), 2u);
  EXPECT_EQ(saved.rois[0].name, "cst-low");
  EXPECT_EQ(regionSpec(saved.rois[0].region), low_.spec());
  EXPECT_EQ(saved.rois[1].name, "cst-high");
  EXPECT_EQ(regionSpec(saved.rois[1].region), high_.spec());
  EXPECT_FALSE(saved.ends_only);

  // Hidden, the dropped fibers leave their pixels; dimmed, they are drawn
  // and the kept ones take the highlight colour.
  const Png hide = readOurPng(hide_png), dim = readOurPng(dim_png), cut = readOurPng(cut_png);
  ASSERT_EQ(hide.width, 160u);
  ASSERT_EQ(dim.width, 160u);
  std::printf("spheres r %.2f and %.2f mm: %zu fibers kept; lit pixels hiding %zu, dimming %zu (%zu highlighted)\n",
              low_.radius, high_.radius, both.size(), litPixels(hide), litPixels(dim), highlightedPixels(dim));
  EXPECT_GT(litPixels(hide), 20u);
  EXPECT_GT(litPixels(dim), 2 * litPixels(hide));
  EXPECT_GT(highlightedPixels(dim), 10u);
  EXPECT_EQ(highlightedPixels(hide), 0u);
  ASSERT_EQ(cut.width, 160u);
  EXPECT_EQ(litPixels(cut), 0u) << "the clip plane reached the frame";
  const Png shown = readOurPng(shown_png);
  EXPECT_EQ(shown.width, 480u);  // the window with the dissection panel open
}

// The right click (script: roi-place): a sphere centred on the fiber drawn
// under the cursor, sized from the scene, that keeps the fibers through it.
TEST_F(GpuDissectionViewer, placedSphereSitsOnTheFiberUnderTheCursor) {
  // Where a fiber is drawn: the covered pixel (3x3) nearest the centre of
  // the scene alone at the window's size and camera.
  const std::string look = dir_.file("look.txt"), scene_png = dir_.file("scene.png"), cache = dir_.file("cache");
  test::writeBytes(look, lines({"wait 1", "screenshot " + scene_png + " 160x120", "quit"}));
  auto r = runViewer("--offscreen --size 160x120 --script " + look + " " + tck_, cache);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Png scene = readOurPng(scene_png);
  ASSERT_EQ(scene.width, 160u);
  auto covered = [&](uint32_t x, uint32_t y) {
    for (uint32_t v = y - 1; v <= y + 1; ++v)
      for (uint32_t u = x - 1; u <= x + 1; ++u)
        if (std::max({scene.at(u, v)[0], scene.at(u, v)[1], scene.at(u, v)[2]}) <= 40) return false;
    return true;
  };
  std::optional<std::pair<uint32_t, uint32_t>> at;
  auto d2 = [](uint32_t x, uint32_t y) {
    return (double(x) - 80) * (double(x) - 80) + (double(y) - 60) * (double(y) - 60);
  };
  for (uint32_t y = 1; y + 1 < 120; ++y)
    for (uint32_t x = 1; x + 1 < 160; ++x)
      if (covered(x, y) && (!at || d2(x, y) < d2(at->first, at->second))) at = {x, y};
  ASSERT_TRUE(at.has_value()) << "nothing drawn";

  const std::string place = dir_.file("place.txt"), set = dir_.file("placed.json"), kept = dir_.file("placed.tck");
  test::writeBytes(place, lines({"wait 1", "roi-place " + std::to_string(at->first) + " " + std::to_string(at->second),
                                 "roi-save " + set, "export-kept " + kept, "quit"}));
  r = runViewer("--offscreen --size 160x120 --script " + place + " " + tck_, cache);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const RoiSet placed = loadRoiSet(set);
  ASSERT_EQ(placed.rois.size(), 1u);
  EXPECT_EQ(placed.rois[0].name, "sphere-1");
  EXPECT_EQ(placed.rois[0].role, RoiRole::Include);
  const auto& sphere = std::get<SphereRegion>(placed.rois[0].region);
  const glm::dvec3 center(sphere.center[0], sphere.center[1], sphere.center[2]);
  // On a fiber: the depth read back puts the centre within a line's width
  // (here about 1 mm) of a point of the phantom.
  double nearest = INFINITY;
  for (size_t s = 0; s < phantom_.streamlineCount(); ++s) nearest = std::min(nearest, closest(s, center));
  std::printf("placed at %.1f, %.1f, %.1f mm, radius %.2f mm, %.3f mm from the nearest point\n", center.x, center.y,
              center.z, double(sphere.radius), nearest);
  EXPECT_LT(nearest, 1.5);
  // 3 % of the scene's diagonal (the phantom spans about 250 mm).
  EXPECT_GT(sphere.radius, 4.0f);
  EXPECT_LT(sphere.radius, 10.0f);
  const Tractogram through = readAllStreamlines(*openTractogram(kept));
  EXPECT_EQ(through.streamlineCount(), keptBy({Sphere{center, double(sphere.radius)}}).size());
  EXPECT_GT(through.streamlineCount(), 0u);
}

// Mesh cuts from a script: a box about the phantom's middle, half its
// extent each way. Hiding what lies outside it leaves a subset of the
// uncut frame's covered pixels, and fewer; hiding what lies inside leaves
// fewer too, and the two cuts share few pixels (only where a fiber inside
// the box is in front of one outside, or the reverse, along the ray). The
// saved set holds the cut and, loaded after a clear, draws the same frame.
// A cut whose OBJ cannot be read is one line and adds nothing.
TEST_F(GpuDissectionViewer, meshCutsHideInsideOrOutsideAndSurviveTheRoiSet) {
  if (test::runCommand("command -v xvfb-run").exit_code != 0) GTEST_SKIP() << "xvfb-run is not installed";
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (size_t i = 0; i < phantom_.pointCount(); ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], double(phantom_.point(i)[k]));
      hi[k] = std::max(hi[k], double(phantom_.point(i)[k]));
    }
  const glm::dvec3 c = 0.5 * (lo + hi), h = 0.25 * (hi - lo);
  char box[160];
  std::snprintf(box, sizeof box, "box:%.2f,%.2f,%.2f,%.2f,%.2f,%.2f", c.x - h.x, c.y - h.y, c.z - h.z, c.x + h.x,
                c.y + h.y, c.z + h.z);
  const std::string missing = dir_.file("no-such-mesh.obj"), set = dir_.file("cuts.json");
  const std::string script = dir_.file("s.txt");
  auto shot = [&](const char* name) { return "screenshot " + dir_.file(name) + " 160x120"; };
  test::writeBytes(script, lines({
                               shot("none.png"),
                               std::string("cut-mesh-add ") + box + ":outside",
                               shot("outside.png"),
                               "cut-mesh-clear",
                               std::string("cut-mesh-add ") + box + ":inside",
                               "cut-mesh-add " + missing + ":outside",
                               shot("inside.png"),
                               "roi-save " + set,
                               "cut-mesh-clear",
                               shot("cleared.png"),
                               "roi-load " + set,
                               shot("reloaded.png"),
                               "quit",
                           }));
  // In a window under Xvfb (the panel drawn with the cuts listed), the
  // screenshots of the scene alone.
  const auto r = runViewer("--size 240x160 --script " + script + " " + tck_, dir_.file("cache"), kXvfb);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  size_t missing_lines = 0;
  for (size_t at = r.output.find(missing); at != std::string::npos; at = r.output.find(missing, at + 1)) ++missing_lines;
  EXPECT_EQ(missing_lines, 1u) << r.output;

  const Png none = readOurPng(dir_.file("none.png")), outside = readOurPng(dir_.file("outside.png"));
  const Png inside = readOurPng(dir_.file("inside.png")), cleared = readOurPng(dir_.file("cleared.png"));
  const Png reloaded = readOurPng(dir_.file("reloaded.png"));
  auto lit = [](const Png& png, uint32_t x, uint32_t y) {
    const uint8_t* p = png.at(x, y);
    return std::max({p[0], p[1], p[2]}) > 40;
  };
  size_t n_none = 0, n_out = 0, n_in = 0, out_not_none = 0, in_not_none = 0, both = 0, reload_differs = 0;
  for (uint32_t y = 0; y < none.height; ++y)
    for (uint32_t x = 0; x < none.width; ++x) {
      const bool a = lit(none, x, y), o = lit(outside, x, y), i = lit(inside, x, y);
      n_none += a;
      n_out += o;
      n_in += i;
      out_not_none += o && !a;
      in_not_none += i && !a;
      both += o && i;
      reload_differs += std::memcmp(inside.at(x, y), reloaded.at(x, y), 3) != 0;
    }
  ASSERT_GT(n_none, 500u);
  EXPECT_LT(n_out, n_none * 9 / 10) << "hiding outside the box hid little";
  EXPECT_GT(n_out, 50u) << "hiding outside the box hid everything";
  EXPECT_LT(n_in, n_none * 95 / 100) << "hiding inside the box hid little";
  EXPECT_LE(out_not_none, n_none / 200) << "a cut drew pixels the uncut frame does not cover";
  EXPECT_LE(in_not_none, n_none / 200);
  EXPECT_LT(both, std::min(n_in, n_out)) << "inside and outside cut the same";
  EXPECT_EQ(reload_differs, 0u) << "the loaded set does not draw the saved cut";
  EXPECT_GT(litPixels(cleared), n_in) << "cut-mesh-clear left a cut";

  const RoiSet saved = loadRoiSet(set);
  ASSERT_EQ(saved.cut_meshes.size(), 1u) << "the unreadable OBJ was added";
  EXPECT_EQ(saved.cut_meshes[0].cut.spec, box);
  EXPECT_TRUE(saved.cut_meshes[0].cut.cull_inside);
  EXPECT_TRUE(saved.cut_meshes[0].enabled);
}

TEST_F(GpuDissectionViewer, malformedRoiSetIsOneLineAndKeepsTheViewerAndItsState) {
  const std::vector<size_t> high_only = keptBy({high_});
  const std::string n_high = std::to_string(high_only.size());
  const std::string bad = dir_.file("bad.json"), script = dir_.file("s.txt");
  test::writeBytes(
      bad, "{\"fibscope_roi_set\": 1, \"rois\": [{\"region\": \"" + high_.spec() + "\", \"colour\": \"red\"}]}");
  test::writeBytes(script, lines({
                               "roi-add cst-high include " + high_.spec(),
                               "expect-kept " + n_high,
                               "roi-load " + bad,
                               "roi-load " + dir_.file("missing.json"),
                               "wait 1",
                               "expect-kept " + n_high,
                               "expect-kept 999",  // fails: the run ends naming this line
                               "quit",
                           }));
  const auto r = runViewer("--offscreen --size 160x120 --script " + script + " " + tck_, dir_.file("cache"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  // Each failed load: one line naming the file and what is wrong.
  std::vector<std::string> output_lines;
  for (size_t start = 0; start < r.output.size();) {
    const size_t end = r.output.find('\n', start);
    output_lines.push_back(r.output.substr(start, end == std::string::npos ? std::string::npos : end - start));
    start = end == std::string::npos ? r.output.size() : end + 1;
  }
  auto count = [&](const std::string& what) {
    return std::count_if(output_lines.begin(), output_lines.end(),
                         [&](const std::string& l) { return l.find(what) != std::string::npos; });
  };
  EXPECT_EQ(count(bad), 1) << r.output;
  EXPECT_EQ(count("fibscope view: " + bad + ": rois[0]: unknown key \"colour\""), 1) << r.output;
  EXPECT_EQ(count("missing.json"), 1) << r.output;
  EXPECT_EQ(count(script + ":6: kept " + n_high + " of 300 fibers"), 1)
      << "the state outlived the bad files: " << r.output;
  EXPECT_EQ(count(script + ":7: expect-kept 999: " + n_high + " of 300 fibers are kept"), 1) << r.output;
}

// Per-fiber scalars: on a TRX whose dps holds "w" (some NaN), the scripted
// ranges keep the count computed here from the array (and the ROI with
// them), the count `fibscope filter --fiber-scalar` reports, and a saved
// set holds the range.
TEST_F(GpuDissectionViewer, scriptedFiberScalarRangesKeepWhatFibscopeFilterKeeps) {
  Tractogram t = phantom_;
  t.per_streamline = {{"w", 1, "float32", {}}};
  uint32_t x = 99;
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    x = x * 1664525u + 1013904223u;
    t.per_streamline[0].values.push_back(s % 29 == 3 ? NAN : float(x >> 8) / float(1 << 24));
  }
  const std::vector<float>& w = t.per_streamline[0].values;
  const std::string trx = dir_.file("w.trx");
  writeTractogram(trx, t, TractogramHeader{});
  auto count = [&](double lo, double hi, bool with_roi) {
    size_t n = 0;
    for (size_t s = 0; s < t.streamlineCount(); ++s)
      n += w[s] >= lo && w[s] <= hi && (!with_roi || closest(s, high_.center) <= high_.radius);
    return n;
  };
  const size_t in_range = count(0.2, 0.7, false), with_roi = count(0.2, 0.7, true), open = count(0.5, INFINITY, true);
  ASSERT_GT(with_roi, 0u);
  ASSERT_LT(with_roi, in_range);
  const auto filtered = test::runFibscope("filter " + trx + " " + dir_.file("f.trx") + " --fiber-scalar w:0.2:0.7");
  ASSERT_EQ(filtered.exit_code, 0) << filtered.output;
  EXPECT_NE(filtered.output.find(": " + std::to_string(in_range) + " of 300 streamlines kept"), std::string::npos)
      << filtered.output;
  const std::string script = dir_.file("w.txt"), set = dir_.file("w.json");
  test::writeBytes(script, lines({
                               "fiber-scalar w 0.2 0.7",
                               "expect-kept " + std::to_string(in_range),
                               "roi-add cst-high include " + high_.spec(),
                               "expect-kept " + std::to_string(with_roi),
                               "fiber-scalar w 0.5 -",
                               "expect-kept " + std::to_string(open),
                               "roi-save " + set,
                               "fiber-scalar-clear",
                               "expect-kept " + std::to_string(keptBy({high_}).size()),
                               "quit",
                           }));
  const auto r = runViewer("--offscreen --size 160x120 --script " + script + " " + trx, dir_.file("cache"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const RoiSet saved = loadRoiSet(set);
  ASSERT_EQ(saved.scalar_ranges.size(), 1u);
  EXPECT_EQ(scalarRangeSpec(saved.scalar_ranges[0].range), "w:0.5:");
}

// A missing array: `render` names the file and its arrays, exit 2, no image.
TEST(GpuScalarRangeCommand, renderWithAnArrayTheInputLacksIsOneLine) {
  const auto info = test::runFibscope("gpu-info");
  if (info.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << info.output;
  test::TempDir dir;
  const std::string tck = test::writePhantomTck(dir, "p.tck", 20, 1), png = dir.file("x.png");
  const auto r = test::runFibscope("render " + tck + " -o " + png + " --fiber-scalar fa:0.3:");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find(tck + ": no per-streamline array \"fa\""), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(png));
}

}  // namespace
}  // namespace fibscope
