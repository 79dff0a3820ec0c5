// The viewer's Bundle action (issue 17 item 1) as a script meets it: the
// active model bundled on a worker while frames go on, with progress; the
// copy added as a model with the same fibers and moved points; the
// original / bundled toggle; save through `fibscope bundle`'s writer, read
// by `fibscope info` and reopened in the viewer. The script parser's new
// commands are tested without a GPU.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "app/viewer/viewer_script.h"
#include "core/error.h"
#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::differingPixels;
using test::drawnPixels;

TEST(ViewerBundlingScript, parsesBundleWaitShowAndSave) {
  const auto steps = parseScript(
      "bundle radius=4 iterations=2 voxel=2 step=1.5 smoothing=0.5 relaxation=0.7 decay=0.9 mode=anisotropic\n"
      "wait-bundle\nshow-model 1\nsave-model 1 out.trk\n",
      "s.txt");
  ASSERT_EQ(steps.size(), 4u);
  const BundleParams& p = std::get<BundleAction>(std::get<ViewerAction>(steps[0].command)).params;
  EXPECT_EQ(p.radius, 4);
  EXPECT_EQ(p.iterations, 2u);
  EXPECT_EQ(p.voxel_mm, 2);
  EXPECT_EQ(p.step_mm, 1.5);
  EXPECT_EQ(p.smoothing, 0.5);
  EXPECT_EQ(p.relaxation, 0.7);
  EXPECT_EQ(p.radius_decay, 0.9);
  EXPECT_EQ(p.mode, BundleMode::Anisotropic);
  EXPECT_TRUE(std::holds_alternative<WaitBundled>(steps[1].command));
  EXPECT_EQ(std::get<ShowOnlyModelAction>(std::get<ViewerAction>(steps[2].command)).model, 1);
  const auto& save = std::get<SaveModelAction>(std::get<ViewerAction>(steps[3].command));
  EXPECT_EQ(save.model, 1);
  EXPECT_EQ(save.path, "out.trk");
  // The defaults are the paper's.
  const auto plain = parseScript("bundle\n", "s.txt");
  EXPECT_EQ(std::get<BundleAction>(std::get<ViewerAction>(plain[0].command)).params.iterations, 15u);
  EXPECT_FALSE(std::get<BundleAction>(std::get<ViewerAction>(plain[0].command)).params.structure_aware);
  const auto aware = parseScript("bundle structure=1 structure-power=3 structure-scale=1.5\n", "s.txt");
  const BundleParams& a = std::get<BundleAction>(std::get<ViewerAction>(aware[0].command)).params;
  EXPECT_TRUE(a.structure_aware);
  EXPECT_EQ(a.structure_power, 3u);
  EXPECT_EQ(a.structure_scale, 1.5);
  for (const char* bad : {"bundle structure=2\n", "bundle structure-power=0\n", "bundle structure-power=2.5\n",
                          "bundle structure-scale=9\n"})
    EXPECT_THROW(parseScript(bad, "s.txt"), Error) << bad;
}

TEST(ViewerBundlingScript, parsesSplitViewOnAndOff) {
  const auto steps = parseScript("split-view 0 1\nsplit-view off\n", "s.txt");
  ASSERT_EQ(steps.size(), 2u);
  const auto& on = std::get<SplitViewAction>(std::get<ViewerAction>(steps[0].command));
  EXPECT_TRUE(on.on);
  EXPECT_EQ(on.left, 0);
  EXPECT_EQ(on.right, 1);
  EXPECT_FALSE(std::get<SplitViewAction>(std::get<ViewerAction>(steps[1].command)).on);
  for (const char* bad : {"split-view\n", "split-view 1\n", "split-view 0 x\n", "split-view -1 2\n",
                          "split-view 0 1 2\n"}) {
    try {
      parseScript(bad, "s.txt");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("s.txt"), std::string::npos) << e.what();
    }
  }
}

TEST(ViewerBundlingScript, malformedBundleLinesNameTheLine) {
  for (const std::string bad : {"bundle radius", "bundle radius=x", "bundle colour=3", "bundle iterations=0",
                                "bundle mode=fuzzy", "bundle relaxation=2", "wait-bundle 3", "show-model",
                                "show-model -1", "save-model 1", "save-model 1 out.png"}) {
    SCOPED_TRACE(bad);
    try {
      parseScript("wait 1\n" + bad + "\n", "s.txt");
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("s.txt:2: ", 0), 0u) << e.what();
    }
  }
}

TEST(ViewerBundlingScript, waitBundleHoldsWhileBundling) {
  ScriptRunner runner(parseScript("bundle iterations=2\nwait-bundle\nquit\n", "s.txt"));
  EXPECT_EQ(runner.nextFrame().size(), 1u);  // bundle; wait-bundle from the next frame on
  EXPECT_TRUE(runner.nextFrame(false, false, true).empty());
  EXPECT_TRUE(runner.nextFrame(false, false, true).empty());
  const auto last = runner.nextFrame(false, false, false);
  ASSERT_EQ(last.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<QuitAction>(last[0]));
  EXPECT_TRUE(runner.finished());
}

class GpuViewerBundling : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::CommandResult runViewer(const std::string& args) {
    return test::runCommand("FIBSCOPE_CACHE_DIR='" + dir_.path() + "' " + FIBSCOPE_EXE + " view --validate " + args);
  }
  test::TempDir dir_;
};

unsigned long long numberAfter(const std::string& text, const std::string& key) {
  const size_t at = text.find(key);
  if (at == std::string::npos) return 0;
  return std::strtoull(text.c_str() + at + key.size(), nullptr, 10);
}

TEST_F(GpuViewerBundling, bundlesWhileFramesGoOnTogglesSavesAndReopens) {
  const std::string original = dir_.file("original.png"), bundled = dir_.file("bundled.png");
  const std::string saved = dir_.file("bundled.tck"), script = dir_.file("s.txt");
  // Eight iterations: about a second here (a dozen frames for each two
  // iterations on an idle host), so the frames drawn meanwhile stay above
  // the bound when another lavapipe test shares the cores.
  test::writeBytes(script, "wait-loaded\nview coronal\nbundle radius=4 iterations=8 voxel=2\nwait-bundle\n"
                           "show-model 0\nwait 1\nscreenshot " + original + " 96x64\n"
                           "show-model 1\nwait 1\nscreenshot " + bundled + " 96x64\n"
                           "save-model 1 " + saved + "\nquit\n");
  const auto r = runViewer("--offscreen --size 160x120 --phantom-streamlines 300 --script " + script);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const size_t line = r.output.find("fibscope view: bundled ");
  ASSERT_NE(line, std::string::npos) << r.output;
  const std::string report = r.output.substr(line, r.output.find('\n', line) - line);
  EXPECT_NE(report.find(": 300 fibers, "), std::string::npos) << report;
  EXPECT_GE(numberAfter(report, "s; "), 3u) << "frames drawn while bundling: " << report;
  EXPECT_GE(numberAfter(report, "bundling, "), 2u) << "progress reports: " << report;
  EXPECT_EQ(report.find("displacement mean 0.000 mm"), std::string::npos) << "the points moved: " << report;
  EXPECT_NE(report.find("; model 1"), std::string::npos) << report;
  EXPECT_GT(differingPixels(test::readOurPng(original), test::readOurPng(bundled)), 50u)
      << "show-model 0 and 1 draw the original and the bundled copy";

  const auto info = test::runFibscope("info " + saved);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("300"), std::string::npos) << info.output;
  const std::string reopened = dir_.file("reopened.png");
  const auto again = runViewer("--offscreen --size 160x120 --frames 2 --screenshot " + reopened + " " + saved);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_GT(test::readOurPng(reopened).width, 0u);
}

TEST_F(GpuViewerBundling, quittingWhileBundlingCancelsTheJobAndLeavesNoFiles) {
  const std::string script = dir_.file("s.txt"), tmp = dir_.file("tmp");
  test::writeBytes(script, "wait-loaded\nbundle radius=4 iterations=1000 voxel=2\nwait 3\nquit\n");
  const auto start = std::chrono::steady_clock::now();
  const auto r = test::runCommand("mkdir -p '" + tmp + "' && TMPDIR='" + tmp + "' FIBSCOPE_CACHE_DIR='" + dir_.path() +
                                  "' " + FIBSCOPE_EXE +
                                  " view --validate --offscreen --size 64x64 --phantom-streamlines 300 --script " + script);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("fibscope view: bundled "), std::string::npos) << r.output;
  EXPECT_LT(seconds, 60.0) << "1000 iterations were not run to the end";
  const auto left = test::runCommand("find '" + tmp + "' -type f | wc -l");
  EXPECT_EQ(std::atoi(left.output.c_str()), 0) << left.output;
}

// Pixels of `half` (a w x h image) that equal `full`'s at column x0 + x
// (RGB within 8 of 255), counted over the pixels drawn in either.
double agreeingDrawnFraction(const test::Png& half, const test::Png& full, uint32_t x0) {
  size_t drawn = 0, agree = 0;
  for (uint32_t y = 0; y < half.height; ++y)
    for (uint32_t x = 0; x < half.width; ++x) {
      const uint8_t* a = half.at(x, y);
      const uint8_t* b = full.at(x0 + x, y);
      const bool lit_a = a[0] + a[1] + a[2] > 30, lit_b = b[0] + b[1] + b[2] > 30;
      if (!lit_a && !lit_b) continue;
      ++drawn;
      agree += std::abs(a[0] - b[0]) <= 8 && std::abs(a[1] - b[1]) <= 8 && std::abs(a[2] - b[2]) <= 8;
    }
  return drawn ? double(agree) / double(drawn) : 0.0;
}

test::Png crop(const test::Png& p, uint32_t x0, uint32_t width) {
  test::Png out;
  out.width = width;
  out.height = p.height;
  for (uint32_t y = 0; y < p.height; ++y)
    out.rgba.insert(out.rgba.end(), p.at(x0, y), p.at(x0, y) + 4 * width);
  return out;
}

// The distance factor the viewer reports when the split view goes on
// ("each half's eye F x as far"); 0 when it reports none.
double splitFactorIn(const std::string& output) {
  const std::string key = "each half's eye ";
  const size_t at = output.find(key);
  return at == std::string::npos ? 0.0 : std::strtod(output.c_str() + at + key.size(), nullptr);
}

// Wheel steps that move the eye `factor` times as far (one step: 1.1x).
std::string dollyOut(double factor) {
  char steps[32];
  std::snprintf(steps, sizeof steps, "%.9f", -std::log(factor) / std::log(1.1));
  return steps;
}

// The split view: the original in the left half, the bundled copy in the
// right, one camera. A half's camera is the full one at half the width with
// the eye F times as far (split_view.h: twice, times the ratio of the two
// models' union to the box the camera was framed on, here the bundled copy
// alone), so each half must show exactly the centre half of that model's
// full-width frame after a dolly to F times the distance; screen-space
// effects off (SSAO and FXAA read neighbours across the crop's edges).
// Turning the split off gives the single view back. A first run reads F
// (the bundling is deterministic), the second dollies by it.
TEST_F(GpuViewerBundling, splitViewShowsTheOriginalLeftAndTheBundledCopyRightFromOneCamera) {
  const std::string before = dir_.file("before.png"), split = dir_.file("split.png"), after = dir_.file("after.png"),
                    full0 = dir_.file("full0.png"), full1 = dir_.file("full1.png"), script = dir_.file("s.txt");
  const std::string setup = "wait-loaded\nview coronal\nset ssao off\nset fxaa off\nset orientation-labels off\n"
                            "set background 0,0,0\nbundle radius=4 iterations=2 voxel=2\nwait-bundle\n";
  const std::string args = "--offscreen --size 160x90 --phantom-streamlines 300 --script " + script;
  test::writeBytes(script, setup + "split-view 0 1\nwait 1\nquit\n");
  const auto first = runViewer(args);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const double factor = splitFactorIn(first.output);
  ASSERT_GE(factor, 2.0) << first.output;
  EXPECT_LT(factor, 2.5) << "a bundled copy hardly smaller than its original: " << first.output;
  test::writeBytes(script, setup + "show-model 0\nwait 1\nscreenshot " + before + " 128x72\n"
                                   "split-view 0 1\nwait 2\nscreenshot " + split + " 128x72\n"
                                   "split-view off\nshow-model 0\nwait 1\nscreenshot " + after + " 128x72\n"
                                   "dolly " + dollyOut(factor) + "\nwait 1\nscreenshot " + full0 + " 128x72\n"
                                   "show-model 1\nwait 1\nscreenshot " + full1 + " 128x72\n"
                                   "split-view 0 9\nquit\n");
  const auto r = runViewer(args);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(splitFactorIn(r.output), factor) << r.output;
  const test::Png a = test::readOurPng(full0), b = test::readOurPng(full1), s = test::readOurPng(split);
  ASSERT_EQ(s.width, 128u);
  ASSERT_EQ(a.width, 128u);
  ASSERT_EQ(b.width, 128u);
  const test::Png left = crop(s, 0, 64), right = crop(s, 64, 64);
  ASSERT_GT(drawnPixels(left), 100u);
  ASSERT_GT(drawnPixels(right), 100u);
  EXPECT_GE(agreeingDrawnFraction(left, a, 32), 0.98) << "left half: the original's centre";
  EXPECT_GE(agreeingDrawnFraction(right, b, 32), 0.98) << "right half: the bundled copy's centre";
  EXPECT_LT(agreeingDrawnFraction(right, a, 32), 0.9) << "the right half is not the original";
  EXPECT_EQ(differingPixels(test::readOurPng(after), test::readOurPng(before)), 0u)
      << "split-view off gives the single view back";
  EXPECT_NE(r.output.find("split-view 0 9: no such model"), std::string::npos) << r.output;
}

// Nothing of a larger model falls outside its half when the camera was
// framed on the smaller one: a tractogram and its copy shrunk to half about
// the box centre, the copy opened with the original hidden (so the camera
// frames the copy alone, as it frames a bundled copy). The halves' eye goes
// back 2 x 2 = 4 times (the union's diagonal is twice the copy's), the left
// half is the centre of the original's frame at 4x the distance, nothing of
// it touches its half's left or right edge, and both models show at one
// scale (the copy's drawn width half the original's, within 2 px). The
// full-width reference is the single view with the original shown again:
// its near and far enclose every visible model, not only the framed copy
// (before, they cut the original's front and back: 77 % agreement).
// A model added within the scene (here a shrunken copy, as a bundled copy
// is) keeps the view the user had turned and zoomed to: with the copy
// hidden again the picture is the one before it was opened.
TEST_F(GpuViewerBundling, addingAModelKeepsTheUsersView) {
  const Tractogram big = test::smallTractogram(60, 3);
  Tractogram small = big;
  for (float& v : small.positions) v *= 0.8f;  // about the origin, inside the original's box
  const std::string big_tck = dir_.file("big.tck"), small_tck = dir_.file("small.tck");
  writeTractogram(big_tck, big, TractogramHeader{});
  writeTractogram(small_tck, small, TractogramHeader{});
  const std::string before = dir_.file("before.png"), after = dir_.file("after.png"),
                    reset = dir_.file("reset.png"), script = dir_.file("s.txt");
  test::writeBytes(script, "wait-loaded\nset ssao off\nset fxaa off\nset orientation-labels off\n"
                           "set background 0,0,0\norbit 240 90\ndolly 2\nwait 1\nscreenshot " + before +
                           " 128x72\nopen " + small_tck + "\nwait-loaded\nmodel 1 hide\nwait 1\nscreenshot " +
                           after + " 128x72\nview reset\nwait 1\nscreenshot " + reset + " 128x72\nquit\n");
  const auto r = runViewer("--offscreen --size 160x90 --script " + script + " " + big_tck);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const test::Png a = test::readOurPng(before), b = test::readOurPng(after), c = test::readOurPng(reset);
  ASSERT_GT(drawnPixels(a), 100u);
  EXPECT_GE(agreeingDrawnFraction(a, b, 0), 0.999) << "the view changed when a model was added";
  // The reset key still frames the default view: another picture.
  EXPECT_LT(agreeingDrawnFraction(a, c, 0), 0.9);
}

TEST_F(GpuViewerBundling, splitViewFramesTheUnionOfItsModelsWhenTheCameraWasFramedOnTheSmaller) {
  const Tractogram big = test::smallTractogram(60, 3);
  Tractogram small = big;
  float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (size_t i = 0; i < big.pointCount(); ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], big.point(i)[k]), hi[k] = std::max(hi[k], big.point(i)[k]);
  for (size_t i = 0; i < small.positions.size(); ++i) {
    const float centre = (lo[i % 3] + hi[i % 3]) / 2;
    small.positions[i] = centre + 0.5f * (small.positions[i] - centre);
  }
  const std::string big_tck = dir_.file("big.tck"), small_tck = dir_.file("small.tck");
  writeTractogram(big_tck, big, TractogramHeader{});
  writeTractogram(small_tck, small, TractogramHeader{});
  const std::string split = dir_.file("split.png"), full0 = dir_.file("full0.png"), full1 = dir_.file("full1.png"),
                    script = dir_.file("s.txt");
  test::writeBytes(script, "wait-loaded\nview coronal\nset ssao off\nset fxaa off\nset orientation-labels off\n"
                           "set background 0,0,0\nmodel 0 hide\nopen " + small_tck + "\nwait-loaded\n"
                           // Adding a model keeps the view (framed on the big one): the reset
                           // key frames the visible, smaller one.
                           "view reset\nwait 2\nsplit-view 0 1\nwait 2\nscreenshot " + split + " 128x72\nsplit-view off\n"
                           "dolly " + dollyOut(4.0) + "\nshow-model 0\nwait 1\nscreenshot " + full0 + " 128x72\n"
                           "show-model 1\nwait 1\nscreenshot " + full1 + " 128x72\nquit\n");
  const auto r = runViewer("--offscreen --size 160x90 --script " + script + " " + big_tck);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NEAR(splitFactorIn(r.output), 4.0, 1e-3) << r.output;
  const test::Png s = test::readOurPng(split), a = test::readOurPng(full0), b = test::readOurPng(full1);
  ASSERT_EQ(s.width, 128u);
  const test::Png left = crop(s, 0, 64), right = crop(s, 64, 64);
  ASSERT_GT(drawnPixels(left), 50u);
  ASSERT_GT(drawnPixels(right), 20u);
  EXPECT_GE(agreeingDrawnFraction(left, a, 32), 0.98) << "left half: the original's centre at 4x";
  EXPECT_GE(agreeingDrawnFraction(right, b, 32), 0.98) << "right half: the copy's centre at 4x";
  // Drawn columns of a half: [first, last].
  auto columns = [](const test::Png& p) {
    int first = -1, last = -1;
    for (uint32_t x = 0; x < p.width; ++x)
      for (uint32_t y = 0; y < p.height; ++y) {
        const uint8_t* c = p.at(x, y);
        if (c[0] + c[1] + c[2] <= 30) continue;
        if (first < 0) first = int(x);
        last = int(x);
      }
    return std::pair<int, int>{first, last};
  };
  const auto [l0, l1] = columns(left);
  const auto [r0, r1] = columns(right);
  EXPECT_GT(l0, 0) << "the original reaches its half's left edge";
  EXPECT_LT(l1, 63) << "the original reaches its half's right edge";
  EXPECT_NEAR(double(r1 - r0 + 1), double(l1 - l0 + 1) / 2, 2.0) << "one scale in both halves";
}

TEST_F(GpuViewerBundling, aSaveToAnExistingFileOrWithoutAModelIsAMessage) {
  const std::string exists = dir_.file("exists.tck"), script = dir_.file("s.txt");
  test::writeBytes(exists, "x");
  test::writeBytes(script, "wait-loaded\nsave-model 0 " + exists + "\nsave-model 5 " + dir_.file("n.tck") +
                               "\nshow-model 7\nquit\n");
  const auto r = runViewer("--offscreen --size 64x64 --phantom-streamlines 50 --script " + script);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(exists), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("save-model 5: no such model"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("show-model 7: no such model"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fibscope
