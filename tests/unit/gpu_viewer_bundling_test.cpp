// The viewer's Bundle action (issue 17 item 1) as a script meets it: the
// active model bundled on a worker while frames go on, with progress; the
// copy added as a model with the same fibers and moved points; the
// original / bundled toggle; save through `fibscope bundle`'s writer, read
// by `fibscope info` and reopened in the viewer. The script parser's new
// commands are tested without a GPU.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>

#include "app/viewer/viewer_script.h"
#include "core/error.h"
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
  test::writeBytes(script, "wait-loaded\nview coronal\nbundle radius=4 iterations=2 voxel=2\nwait-bundle\n"
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
