// The viewer's anatomical image (viewer_anatomy.h) as a user meets it: a
// dropped .nii/.nii.gz goes to the anatomy (a tractogram to the models),
// I/J/K choose the active slice and Page Up/Down move it within the volume,
// a script's `anatomy FILE` shows the slices under the fibers, a file that
// cannot be shown leaves a one-line message and the viewer going on (and
// ends the run when the command line named it).
#include <gtest/gtest.h>

#include <GLFW/glfw3.h>

#include <algorithm>
#include <string>

#include "app/viewer/viewer_anatomy.h"
#include "app/viewer/viewer_input.h"
#include "app/viewer/viewer_script.h"
#include "core/error.h"
#include "test_support.h"

namespace fibscope {
namespace {

InputEvent keyEvent(int key, bool shift = false) {
  InputEvent e;
  e.type = InputEvent::Type::Key;
  e.key = key;
  e.pressed = true;
  e.shift = shift;
  return e;
}

TEST(ViewerAnatomyInput, droppedImagesGoToTheAnatomyAndTractogramsToTheModels) {
  InputMapper m;
  InputEvent drop;
  drop.type = InputEvent::Type::Drop;
  drop.paths = {"/data/T1.nii.gz", "/data/tracks.tck", "/data/FA.NII"};
  const auto a = m.map(drop, false, false);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(std::get<AnatomyAction>(a[0]).path, "/data/T1.nii.gz");
  EXPECT_EQ(std::get<OpenAction>(a[1]).path, "/data/tracks.tck");
  EXPECT_EQ(std::get<AnatomyAction>(a[2]).path, "/data/FA.NII");
  EXPECT_FALSE(isNiftiPath("tracks.trx"));
  EXPECT_FALSE(isNiftiPath("nii"));
}

TEST(ViewerAnatomyInput, ijkChooseTheActiveSliceAndPageKeysMoveIt) {
  InputMapper m;
  const std::pair<int, const char*> choices[] = {{GLFW_KEY_I, "i"}, {GLFW_KEY_J, "j"}, {GLFW_KEY_K, "k"}};
  for (const auto& [k, axis] : choices) {
    const auto a = m.map(keyEvent(k), false, false);
    ASSERT_EQ(a.size(), 1u);
    EXPECT_EQ(std::get<SetAction>(a[0]).key, "active-slice");
    EXPECT_EQ(std::get<SetAction>(a[0]).value, axis);
  }
  EXPECT_EQ(std::get<SliceStepAction>(m.map(keyEvent(GLFW_KEY_PAGE_UP), false, false)[0]).voxels, 1.0);
  EXPECT_EQ(std::get<SliceStepAction>(m.map(keyEvent(GLFW_KEY_PAGE_DOWN), false, false)[0]).voxels, -1.0);
  EXPECT_EQ(std::get<SliceStepAction>(m.map(keyEvent(GLFW_KEY_PAGE_UP, true), false, false)[0]).voxels, 10.0);
  EXPECT_TRUE(m.map(keyEvent(GLFW_KEY_PAGE_UP), false, /*want_keyboard=*/true).empty());  // typing in a panel

  ViewerState state;
  stepActiveSlice(state, 3);  // no volume: nothing moves
  EXPECT_EQ(state.settings.slice_k, 0.0f);
  state.anatomy.path = "t1.nii";
  state.anatomy.dims[0] = 10, state.anatomy.dims[1] = 20, state.anatomy.dims[2] = 5;
  state.settings.active_slice = SliceAxis::J;
  state.settings.slice_j = 18;
  stepActiveSlice(state, 10);
  EXPECT_EQ(state.settings.slice_j, 19.0f);  // the last voxel
  stepActiveSlice(state, -25);
  EXPECT_EQ(state.settings.slice_j, 0.0f);
  EXPECT_EQ(state.settings.slice_i, 0.0f);
}

TEST(ViewerAnatomyInput, theScriptShowsAnImageWithAnatomyFile) {
  const auto steps = parseScript("anatomy /data/T1.nii.gz\nset slice-k 40\n", "s.txt");
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_EQ(std::get<AnatomyAction>(std::get<ViewerAction>(steps[0].command)).path, "/data/T1.nii.gz");
  for (const std::string bad : {"anatomy", "anatomy a.nii b.nii", "set slice-k -1", "set active-slice x",
                                "set anatomy-opacity 2"}) {
    SCOPED_TRACE(bad);
    const std::string message = test::errorOf([&] { parseScript("view axial\n" + bad + "\n", "s.txt"); });
    EXPECT_EQ(message.rfind("s.txt:2: ", 0), 0u) << message;
  }
}

// --- the viewer (Vulkan) ---------------------------------------------------

class GpuViewerAnatomy : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::CommandResult runViewer(const std::string& args) {
    return test::runCommand("FIBSCOPE_CACHE_DIR='" + dir_.path() + "' " + FIBSCOPE_EXE +
                            " view --validate --phantom-streamlines 300 " + args);
  }
  test::TempDir dir_;
};

// Pixels of neutral grey brighter than the background: the slice's.
size_t greyPixels(const test::Png& png) {
  size_t n = 0;
  for (uint32_t y = 0; y < png.height; ++y)
    for (uint32_t x = 0; x < png.width; ++x) {
      const uint8_t* p = png.at(x, y);
      n += p[0] == p[1] && p[1] == p[2] && p[0] > 60;
    }
  return n;
}

TEST_F(GpuViewerAnatomy, aScriptedAnatomyShowsItsSliceAndABadOneIsAMessage) {
  const std::string python = test::pythonWithNibabel();
  if (python.empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel and numpy";
  const std::string head = dir_.file("head.nii.gz"), bad = dir_.file("bad.nii");
  const auto made = test::runCommand(python + " " + test::toolPath("anatomy_make.py") + " head " + head);
  ASSERT_EQ(made.exit_code, 0) << made.output;
  test::writeBytes(bad, std::string(400, 'x'));
  const std::string before = dir_.file("before.png"), with = dir_.file("with.png"), after = dir_.file("after.png");
  const std::string script = dir_.file("s.txt");
  test::writeBytes(script, "wait-loaded\nview axial\nwait 1\nscreenshot " + before + " 96x64\n" +
                               "anatomy " + head + "\nset show-slice-i off\nset show-slice-j off\nwait 1\n" +
                               "screenshot " + with + " 96x64\nanatomy " + bad + "\nwait 1\nscreenshot " + after +
                               " 96x64\nquit\n");
  const auto r = runViewer("--offscreen --size 320x200 --no-orientation-labels --script " + script);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fibscope view: " + bad + ": "), std::string::npos) << r.output;
  const size_t none = greyPixels(test::readOurPng(before));
  const size_t shown = greyPixels(test::readOurPng(with));
  EXPECT_GT(shown, 96u * 64u / 5) << "the axial slice under the phantom";
  EXPECT_LT(none, shown / 10);
  EXPECT_EQ(greyPixels(test::readOurPng(after)), shown) << "the bad file left the slice as it was";
}

TEST_F(GpuViewerAnatomy, aCommandLineAnatomyThatCannotBeShownEndsTheRunWithOneLine) {
  const std::string bad = dir_.file("missing.nii.gz");
  const auto r = runViewer("--offscreen --size 64x64 --frames 2 --anatomy " + bad);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fibscope
