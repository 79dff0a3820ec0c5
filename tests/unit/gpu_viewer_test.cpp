// `fibscope view` as a user and a script meet it: offscreen and (under Xvfb)
// windowed runs that write a screenshot with the tractogram and the panels,
// a scripted session through the same actions as the mouse and panels, and
// one-line errors for malformed scripts. The script parser and the input
// mapping are pure and tested without a GPU.
#include <gtest/gtest.h>

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/recent_files.h"
#include "app/viewer/viewer_input.h"
#include "app/viewer/viewer_script.h"
#include "codec/compressor.h"
#include "codec/fbl_reader.h"
#include "core/error.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "test_support.h"

namespace fibscope {
namespace {

// --- the script parser (no GPU) ---------------------------------------------

TEST(ViewerScript, parsesEveryCommandSkippingCommentsAndBlankLines) {
  const auto steps = parseScript(
      "# a session\n"
      "orbit 10 -5\n"
      "\n"
      "pan 3 4   # drag\n"
      "dolly -2.5\n"
      "view axial\n"
      "view reset\n"
      "fov 45\n"
      "set color solid\n"
      "set background 0.1,0.2,0.3\n"
      "wait 3\n"
      "screenshot out.png 64x48\n"
      "screenshot shown.png\n"
      "quit\n",
      "s.txt");
  ASSERT_EQ(steps.size(), 12u);
  EXPECT_EQ(steps[0].line, 2);
  const auto& orbit = std::get<OrbitAction>(std::get<ViewerAction>(steps[0].command));
  EXPECT_EQ(orbit.dx, 10);
  EXPECT_EQ(orbit.dy, -5);
  EXPECT_EQ(steps[1].line, 4);
  EXPECT_EQ(std::get<PanAction>(std::get<ViewerAction>(steps[1].command)).dy, 4);
  EXPECT_EQ(std::get<DollyAction>(std::get<ViewerAction>(steps[2].command)).steps, -2.5);
  EXPECT_EQ(std::get<ViewAction>(std::get<ViewerAction>(steps[3].command)).view, StandardView::Axial);
  EXPECT_FALSE(std::get<ViewAction>(std::get<ViewerAction>(steps[4].command)).view.has_value());
  EXPECT_EQ(std::get<FovAction>(std::get<ViewerAction>(steps[5].command)).degrees, 45);
  EXPECT_EQ(std::get<SetAction>(std::get<ViewerAction>(steps[6].command)).value, "solid");
  EXPECT_EQ(std::get<WaitFrames>(steps[8].command).frames, 3u);
  const auto& shot = std::get<ScreenshotAction>(std::get<ViewerAction>(steps[9].command));
  EXPECT_EQ(shot.path, "out.png");
  EXPECT_EQ(shot.width, 64u);
  EXPECT_EQ(shot.height, 48u);
  EXPECT_EQ(std::get<ScreenshotAction>(std::get<ViewerAction>(steps[10].command)).width, 0u);
  EXPECT_TRUE(std::holds_alternative<QuitAction>(std::get<ViewerAction>(steps[11].command)));
}

TEST(ViewerScript, malformedLinesNameTheFileAndLine) {
  for (const std::string bad :
       {"orbit 1", "orbit a b", "pan 1 2 3", "dolly", "view top", "fov 5", "fov 120", "set color red",
        "set width 9", "set ssao maybe", "set background 2,0,0", "set speed 3", "wait 0", "wait 1.5",
        "screenshot out.jpg", "screenshot out.png 0x5", "quit now", "jump 3", "orbit nan 1", "resize 400",
        "resize 8 8", "resize 400.5 300", "resize 20000 300", "set ao-scales 6", "set colormap jet",
        "set scalar-range 5,1", "set fxaa maybe", "set dim 2"}) {
    SCOPED_TRACE(bad);
    try {
      parseScript("view axial\n# fine\n" + bad + "\nquit\n", "session.txt");
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("session.txt:3: ", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(ViewerScript, settingsApplyOnlyWhenValid) {
  RenderSettings s;
  applySetting(s, "pipeline", "lines");
  applySetting(s, "culling", "none");
  applySetting(s, "lighting", "none");
  applySetting(s, "width", "2.5");
  applySetting(s, "ssao", "off");
  EXPECT_EQ(s.pipeline, RenderPipeline::Lines);
  EXPECT_EQ(s.culling, CullingMode::None);
  EXPECT_EQ(s.lighting, Lighting::None);
  EXPECT_EQ(s.line_width_px, 2.5f);
  EXPECT_FALSE(s.ssao);
  EXPECT_THROW(applySetting(s, "width", "0.5"), Error);
  EXPECT_EQ(s.line_width_px, 2.5f);  // unchanged by the failure
}

TEST(ViewerScript, parsesPickingAndSelectionCommands) {
  const auto steps = parseScript(
      "pick 10 20\n"
      "pick 3.5 4 add\n"
      "clear-selection\n"
      "export-selection out.tck\n"
      "\n"
      "expect-selected 2\n",
      "s.txt");
  ASSERT_EQ(steps.size(), 5u);
  const auto& pick = std::get<PickAction>(std::get<ViewerAction>(steps[0].command));
  EXPECT_EQ(pick.x, 10);
  EXPECT_EQ(pick.y, 20);
  EXPECT_FALSE(pick.add);
  const auto& add = std::get<PickAction>(std::get<ViewerAction>(steps[1].command));
  EXPECT_EQ(add.x, 3.5);
  EXPECT_TRUE(add.add);
  EXPECT_TRUE(std::holds_alternative<ClearSelectionAction>(std::get<ViewerAction>(steps[2].command)));
  EXPECT_EQ(std::get<ExportSelectionAction>(std::get<ViewerAction>(steps[3].command)).path, "out.tck");
  const auto& expect = std::get<ExpectSelectedAction>(std::get<ViewerAction>(steps[4].command));
  EXPECT_EQ(expect.count, 2u);
  EXPECT_EQ(expect.where, "s.txt:6");  // a failed expectation names its line
}

TEST(ViewerScript, malformedPickingLinesNameTheFileAndLine) {
  for (const std::string bad :
       {"pick 1", "pick a 2", "pick -1 2", "pick 1 70000", "pick 1 2 toggle", "pick 1 2 add more",
        "clear-selection now", "export-selection", "export-selection out.png", "expect-selected",
        "expect-selected -1", "expect-selected 1.5"}) {
    SCOPED_TRACE(bad);
    try {
      parseScript("wait 1\n" + bad + "\n", "session.txt");
      ADD_FAILURE() << "no error";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind("session.txt:2: ", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
}

TEST(ViewerScript, runnerHoldsEachWaitForItsFrames) {
  ScriptRunner runner(parseScript("orbit 1 0\nwait 2\ndolly 1\nview axial\nwait 1\nquit\n", "s"));
  EXPECT_EQ(runner.nextFrame().size(), 1u);  // orbit, then the first waited frame
  EXPECT_EQ(runner.nextFrame().size(), 0u);  // the second
  EXPECT_EQ(runner.nextFrame().size(), 2u);  // dolly, view; then wait 1
  EXPECT_FALSE(runner.finished());
  const auto last = runner.nextFrame();
  ASSERT_EQ(last.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<QuitAction>(last[0]));
  EXPECT_TRUE(runner.finished());
}

// --- the input mapping (no GPU) ---------------------------------------------

InputEvent cursor(double x, double y) {
  InputEvent e;
  e.type = InputEvent::Type::CursorMoved;
  e.x = x;
  e.y = y;
  return e;
}
InputEvent button(int b, bool pressed, bool shift = false) {
  InputEvent e;
  e.type = InputEvent::Type::MouseButton;
  e.button = b;
  e.pressed = pressed;
  e.shift = shift;
  return e;
}
InputEvent key(int k) {
  InputEvent e;
  e.type = InputEvent::Type::Key;
  e.key = k;
  e.pressed = true;
  return e;
}

TEST(ViewerInput, dragsOrbitPanAndWheelDolliesAsMrview) {
  InputMapper m;
  EXPECT_TRUE(m.map(cursor(100, 100), false, false).empty());
  EXPECT_TRUE(m.map(button(InputEvent::kLeft, true), false, false).empty());
  auto a = m.map(cursor(110, 95), false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(std::get<OrbitAction>(a[0]).dx, 10);
  EXPECT_EQ(std::get<OrbitAction>(a[0]).dy, -5);
  m.map(button(InputEvent::kLeft, false), false, false);
  EXPECT_TRUE(m.map(cursor(120, 95), false, false).empty());  // released: no drag

  m.map(button(InputEvent::kMiddle, true), false, false);
  a = m.map(cursor(125, 97), false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(std::get<PanAction>(a[0]).dx, 5);
  m.map(button(InputEvent::kMiddle, false), false, false);

  m.map(button(InputEvent::kLeft, true, /*shift=*/true), false, false);
  a = m.map(cursor(126, 97), false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_TRUE(std::holds_alternative<PanAction>(a[0]));
  m.map(button(InputEvent::kLeft, false), false, false);

  InputEvent wheel;
  wheel.type = InputEvent::Type::Scroll;
  wheel.y = 2;
  a = m.map(wheel, false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(std::get<DollyAction>(a[0]).steps, 2);
}

TEST(ViewerInput, imguiGetsTheMouseFirst) {
  InputMapper m;
  m.map(cursor(10, 10), true, false);
  m.map(button(InputEvent::kLeft, true), /*want_mouse=*/true, false);  // a press on a panel
  EXPECT_TRUE(m.map(cursor(40, 10), false, false).empty());          // stays with the panel
  InputEvent wheel;
  wheel.type = InputEvent::Type::Scroll;
  wheel.y = 1;
  EXPECT_TRUE(m.map(wheel, true, false).empty());
}

InputEvent click(bool pressed, bool control) {
  InputEvent e = button(InputEvent::kLeft, pressed);
  e.control = control;
  return e;
}

TEST(ViewerInput, clickPicksAtThePressAndCtrlClickAdds) {
  InputMapper m;
  m.map(cursor(50, 60), false, false);
  EXPECT_TRUE(m.map(click(true, false), false, false).empty());
  m.map(cursor(52, 61), false, false);  // within the slop: still a click (the orbit follows)
  auto a = m.map(click(false, false), false, false);
  ASSERT_EQ(a.size(), 1u);
  const auto& pick = std::get<PickAction>(a[0]);
  EXPECT_EQ(pick.x, 50);  // where it was pressed
  EXPECT_EQ(pick.y, 60);
  EXPECT_FALSE(pick.add);

  m.map(click(true, /*control=*/true), false, false);
  a = m.map(click(false, true), false, false);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_TRUE(std::get<PickAction>(a[0]).add);
}

TEST(ViewerInput, dragsShiftClicksAndPanelClicksDoNotPick) {
  InputMapper m;
  m.map(cursor(50, 60), false, false);
  m.map(click(true, false), false, false);
  m.map(cursor(54, 60), false, false);  // 4 px: a drag
  m.map(cursor(50, 60), false, false);  // back where it started: still a drag
  for (const auto& action : m.map(click(false, false), false, false))
    EXPECT_FALSE(std::holds_alternative<PickAction>(action));

  m.map(button(InputEvent::kLeft, true, /*shift=*/true), false, false);  // pan
  EXPECT_TRUE(m.map(button(InputEvent::kLeft, false, true), false, false).empty());
  m.map(click(true, false), /*want_mouse=*/true, false);  // on a panel
  EXPECT_TRUE(m.map(click(false, false), true, false).empty());
  m.map(button(InputEvent::kRight, true), false, false);  // places a ROI (dissection), picks no fiber
  for (const auto& action : m.map(button(InputEvent::kRight, false), false, false))
    EXPECT_FALSE(std::holds_alternative<PickAction>(action));
}

TEST(ViewerInput, keysSelectStandardViewsResetAndScreenshot) {
  InputMapper m;
  const std::pair<int, std::optional<StandardView>> views[] = {
      {GLFW_KEY_1, StandardView::Sagittal}, {GLFW_KEY_S, StandardView::Sagittal},
      {GLFW_KEY_2, StandardView::Coronal},  {GLFW_KEY_C, StandardView::Coronal},
      {GLFW_KEY_3, StandardView::Axial},    {GLFW_KEY_A, StandardView::Axial},
      {GLFW_KEY_R, std::nullopt}};
  for (const auto& [k, view] : views) {
    const auto a = m.map(key(k), false, false);
    ASSERT_EQ(a.size(), 1u);
    EXPECT_EQ(std::get<ViewAction>(a[0]).view, view);
  }
  for (int k : {GLFW_KEY_F12, GLFW_KEY_P}) {
    const auto a = m.map(key(k), false, false);
    ASSERT_EQ(a.size(), 1u);
    EXPECT_TRUE(std::holds_alternative<ScreenshotAction>(a[0]));
  }
  EXPECT_TRUE(m.map(key(GLFW_KEY_1), false, /*want_keyboard=*/true).empty());  // typing in a panel
}

// --- the viewer (Vulkan) ---------------------------------------------------

using test::Png;
using test::readOurPng;

// Pixels in [x0, x1) x [y0, y1) brighter than the black background.
double coverage(const Png& png, uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1) {
  size_t lit = 0;
  for (uint32_t y = y0; y < y1; ++y)
    for (uint32_t x = x0; x < x1; ++x) {
      const uint8_t* p = png.at(x, y);
      if (std::max({p[0], p[1], p[2]}) > 40) ++lit;
    }
  return double(lit) / double((x1 - x0) * (y1 - y0));
}

// The ImGui menu bar along the top: a grey band (style colour MenuBarBg)
// over the whole width, a few rows down.
double menuBarShare(const Png& png) {
  size_t grey = 0;
  for (uint32_t x = 0; x < png.width; ++x) {
    const uint8_t* p = png.at(x, 3);
    if (p[0] > 20 && p[0] < 60 && std::abs(p[0] - p[1]) < 6 && std::abs(p[1] - p[2]) < 6) ++grey;
  }
  return double(grey) / png.width;
}

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// The .fbl cache of the viewer runs (the phantom goes through it too): one
// directory per test process unless a test names its own, never the
// user's cache.
const std::string& processCacheDir() {
  static const test::TempDir dir;
  return dir.path();
}

// The child is leak-checked under ASan: see gpu_cli_render_test.cpp.
test::CommandResult runViewer(const std::string& args, const std::string& prefix = "",
                              const std::string& cache_dir = "") {
  return test::runCommand(prefix + "FIBSCOPE_CACHE_DIR='" + (cache_dir.empty() ? processCacheDir() : cache_dir) + "' " +
                          FIBSCOPE_EXE + " view --validate --phantom-streamlines 300 " + args);
}

class GpuViewer : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  // The scene (right half below the overlay) shows the tractogram, the
  // panels are drawn.
  static void expectSceneAndPanels(const Png& png) {
    ASSERT_EQ(png.width, 320u);
    ASSERT_EQ(png.height, 200u);
    EXPECT_GT(coverage(png, 160, 130, 320, 200), 0.02);
    EXPECT_GT(menuBarShare(png), 0.8);
  }
  test::TempDir dir_;
};

TEST_F(GpuViewer, offscreenRunWritesTheWindowWithTractogramAndPanels) {
  const std::string png = dir_.file("x.png");
  const auto r = runViewer("--offscreen --size 320x200 --frames 3 --screenshot " + png);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  expectSceneAndPanels(readOurPng(png));
}

TEST_F(GpuViewer, windowedRunUnderXvfbPresentsThroughASwapchain) {
  if (test::runCommand("command -v xvfb-run").exit_code != 0) GTEST_SKIP() << "xvfb-run is not installed";
  const std::string png = dir_.file("x.png");
  // -a: a free display number (tests may run in parallel).
  const auto r = runViewer("--size 320x200 --frames 3 --screenshot " + png,
                           "xvfb-run -a -s '-screen 0 640x480x24' env ");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("offscreen"), std::string::npos) << "no window was made: " << r.output;
  expectSceneAndPanels(readOurPng(png));
}

// --no-vsync asks the surface for mailbox or immediate presentation (Xvfb's
// lavapipe surface offers both); the default waits for vertical sync (FIFO).
TEST_F(GpuViewer, noVsyncPresentsWithoutWaitingForVerticalSync) {
  if (test::runCommand("command -v xvfb-run").exit_code != 0) GTEST_SKIP() << "xvfb-run is not installed";
  const std::string prefix = "xvfb-run -a -s '-screen 0 640x480x24' env ";
  const auto fifo = runViewer("--size 320x200 --frames 2", prefix);
  ASSERT_EQ(fifo.exit_code, 0) << fifo.output;
  EXPECT_NE(fifo.output.find("present mode fifo"), std::string::npos) << fifo.output;
  const std::string png = dir_.file("nv.png");
  const auto r = runViewer("--no-vsync --size 320x200 --frames 3 --screenshot " + png, prefix);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("present mode fifo"), std::string::npos) << r.output;
  EXPECT_TRUE(r.output.find("present mode mailbox") != std::string::npos ||
              r.output.find("present mode immediate") != std::string::npos)
      << r.output;
  expectSceneAndPanels(readOurPng(png));
}

TEST_F(GpuViewer, scriptedSessionRunsCleanUnderValidation) {
  const std::string script = dir_.file("session.txt");
  const std::string scene_png = dir_.file("scene.png"), shown_png = dir_.file("shown.png");
  test::writeBytes(script,
                   "# camera moves, mode changes, standard views\n"
                   "orbit 40 10\n"
                   "pan 5 -3\n"
                   "dolly 2\n"
                   "wait 2\n"
                   "view sagittal\n"
                   "set color fiber\n"
                   "set lighting none\n"
                   "set culling frustum\n"
                   "wait 1\n"
                   "view axial\n"
                   "set pipeline raw-compute\n"
                   "set ssao off\n"
                   "fov 40\n"
                   "wait 1\n"
                   "set pipeline compute\n"
                   "view reset\n"
                   "screenshot " + scene_png + " 96x64\n"
                   "screenshot " + shown_png + "\n"
                   "wait 1\n"
                   "quit\n");
  const auto r = runViewer("--offscreen --size 320x200 --script " + script);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Png scene = readOurPng(scene_png);
  ASSERT_EQ(scene.width, 96u);
  ASSERT_EQ(scene.height, 64u);
  EXPECT_GT(coverage(scene, 0, 0, 96, 64), 0.05);  // the scene alone, no panels
  EXPECT_LT(menuBarShare(scene), 0.5);
  const Png shown = readOurPng(shown_png);
  EXPECT_EQ(shown.width, 320u);
  EXPECT_GT(menuBarShare(shown), 0.8);
}

// A resize mid-run: the frame targets, the presentation image and (in a
// window) the swapchain are made again; the screenshots have the new sizes
// and still show the scene, with no validation message.
void expectResizedRun(const test::CommandResult& r, const std::string& middle, const std::string& last) {
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Png m = readOurPng(middle), l = readOurPng(last);
  EXPECT_EQ(m.width, 400u);
  EXPECT_EQ(m.height, 300u);
  EXPECT_GT(coverage(m, 200, 150, 400, 300), 0.02) << "the scene after the first resize";
  EXPECT_EQ(l.width, 360u);
  EXPECT_EQ(l.height, 240u);
  EXPECT_GT(coverage(l, 180, 120, 360, 240), 0.02) << "the scene after the second resize";
}

std::string resizeScript(test::TempDir& dir, const std::string& middle) {
  const std::string script = dir.file("resize.txt");
  test::writeBytes(script, "wait-loaded\nwait 2\nresize 400 300\nwait 3\nscreenshot " + middle +
                               "\nresize 360 240\nwait 3\nquit\n");
  return script;
}

TEST_F(GpuViewer, offscreenResizeRemakesTheTargets) {
  const std::string middle = dir_.file("middle.png"), last = dir_.file("last.png");
  const auto r =
      runViewer("--offscreen --size 320x200 --script " + resizeScript(dir_, middle) + " --screenshot " + last);
  expectResizedRun(r, middle, last);
}

TEST_F(GpuViewer, windowResizeUnderXvfbRemakesTheSwapchain) {
  if (test::runCommand("command -v xvfb-run").exit_code != 0) GTEST_SKIP() << "xvfb-run is not installed";
  const std::string middle = dir_.file("middle.png"), last = dir_.file("last.png");
  const auto r = runViewer("--size 320x200 --script " + resizeScript(dir_, middle) + " --screenshot " + last,
                           "xvfb-run -a -s '-screen 0 640x480x24' env ");
  EXPECT_EQ(r.output.find("offscreen"), std::string::npos) << "no window was made: " << r.output;
  expectResizedRun(r, middle, last);
}

TEST_F(GpuViewer, malformedScriptLineIsAOneLineErrorWithItsLineNumber) {
  const std::string script = dir_.file("bad.txt");
  test::writeBytes(script, "orbit 1 2\n\nview upside-down\n");
  const auto r = runViewer("--offscreen --size 64x64 --script " + script);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find(script + ":3:"), std::string::npos) << r.output;
}

TEST_F(GpuViewer, badOptionsAreOneLineErrors) {
  for (const std::string options : {"--size 0x10", "--screenshot x.jpg", "--color red", "--script /nonexistent"}) {
    SCOPED_TRACE(options);
    const auto r = runViewer("--offscreen " + options);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(lineCount(r.output), 1) << r.output;
  }
}


// --- picking and the selection (Vulkan) -------------------------------------

bool covered(const Png& png, uint32_t x, uint32_t y) {
  const uint8_t* p = png.at(x, y);
  return std::max({p[0], p[1], p[2]}) > 40;
}

// The highlight colour (RenderSettings' default 1, 0.8, 0.1) under the
// lighting: any brightness, that chromaticity.
bool highlightColoured(const Png& png, uint32_t x, uint32_t y) {
  const uint8_t* p = png.at(x, y);
  const double r = p[0], g = p[1], b = p[2];
  return r > 60 && std::abs(g / r - 0.8) < 0.08 && b / r < 0.2;
}

// Points of streamline `s` of `t` equal those of streamline `u` of `other`.
bool sameStreamline(const Tractogram& t, size_t s, const Tractogram& other, size_t u) {
  if (t.pointsIn(s) != other.pointsIn(u)) return false;
  return std::equal(t.positions.begin() + std::ptrdiff_t(3 * t.offsets[s]),
                    t.positions.begin() + std::ptrdiff_t(3 * t.offsets[s + 1]),
                    other.positions.begin() + std::ptrdiff_t(3 * other.offsets[u]));
}

// The phantom fibers equal to streamline `s` of `t` (bit for bit).
std::vector<size_t> matches(const Tractogram& phantom, const Tractogram& t, size_t s) {
  std::vector<size_t> found;
  for (size_t u = 0; u < phantom.streamlineCount(); ++u)
    if (sameStreamline(t, s, phantom, u)) found.push_back(u);
  return found;
}

TEST_F(GpuViewer, scriptedPicksSelectHighlightAndExportTheFiberUnderThePixel) {
  // A small phantom compressed to a .fbl: the viewer opens it as is, and its
  // decode (what `fibscope decompress` gives) is the reference.
  const std::string fbl = dir_.file("p.fbl");
  CompressOptions options;
  options.terminal_progress = false;
  options.threads = 1;
  compressTractogram(
      [] {
        PhantomOptions p;
        p.streamlines = 300;
        p.seed = 3;
        p.threads = 1;
        return openPhantom(p);
      },
      fbl, options);
  const Tractogram phantom = readAllStreamlines(*openFbl(fbl));

  // The scene alone at the window's size and camera: which pixels are drawn.
  const std::string script1 = dir_.file("look.txt"), scene_png = dir_.file("scene.png");
  test::writeBytes(script1, "wait 2\nscreenshot " + scene_png + " 320x200\nquit\n");
  // No orientation labels: the image's drawn pixels must be the fibers'.
  auto r = runViewer("--offscreen --size 320x200 --no-orientation-labels --script " + script1 + " " + fbl);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Png scene = readOurPng(scene_png);
  ASSERT_EQ(scene.width, 320u);
  // A: the covered pixel (whole 3x3 block covered) nearest the centre; B:
  // the such pixel farthest from A (another fiber there); C: a pixel with
  // nothing drawn within 3 px.
  std::optional<std::pair<uint32_t, uint32_t>> a, b, c;
  auto block = [&](uint32_t x, uint32_t y, int radius, bool want) {
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx)
        if (covered(scene, uint32_t(int(x) + dx), uint32_t(int(y) + dy)) != want) return false;
    return true;
  };
  auto dist2 = [](uint32_t x0, uint32_t y0, uint32_t x1, uint32_t y1) {
    return (double(x0) - x1) * (double(x0) - x1) + (double(y0) - y1) * (double(y0) - y1);
  };
  for (uint32_t y = 3; y + 3 < scene.height; ++y)
    for (uint32_t x = 3; x + 3 < scene.width; ++x) {
      if (block(x, y, 1, true) && (!a || dist2(x, y, 160, 100) < dist2(a->first, a->second, 160, 100))) a = {x, y};
      if (!c && block(x, y, 3, false)) c = {x, y};
    }
  ASSERT_TRUE(a && c) << "no covered or no empty pixel in the scene";
  for (uint32_t y = 3; y + 3 < scene.height; ++y)
    for (uint32_t x = 3; x + 3 < scene.width; ++x)
      if (block(x, y, 1, true) &&
          (!b || dist2(x, y, a->first, a->second) > dist2(b->first, b->second, a->first, a->second)))
        b = {x, y};
  ASSERT_TRUE(b);
  auto at = [](const std::pair<uint32_t, uint32_t>& p) {
    return std::to_string(p.first) + " " + std::to_string(p.second);
  };

  const std::string script2 = dir_.file("pick.txt"), sel_png = dir_.file("sel.png");
  const std::string one_tck = dir_.file("one.tck"), two_tck = dir_.file("two.tck");
  test::writeBytes(script2,
                   "wait 2\n"
                   "pick " + at(*a) + "\n"
                   "expect-selected 1\n"
                   "export-selection " + one_tck + "\n"
                   "screenshot " + sel_png + " 320x200\n"
                   "wait 1\n"
                   "pick " + at(*c) + "\n"  // the background clears the selection
                   "expect-selected 0\n"
                   "pick " + at(*a) + "\n"
                   "pick " + at(*b) + " add\n"
                   "expect-selected 2\n"
                   "export-selection " + two_tck + "\n"
                   "pick " + at(*a) + " add\n"  // ctrl-click on a selected fiber removes it
                   "expect-selected 1\n"
                   "clear-selection\n"
                   "expect-selected 0\n"
                   "wait 1\n"
                   "quit\n");
  r = runViewer("--offscreen --size 320x200 --no-orientation-labels --script " + script2 + " " + fbl);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const Tractogram one = readAllStreamlines(*openTractogram(one_tck));
  ASSERT_EQ(one.streamlineCount(), 1u);
  const std::vector<size_t> fiber_a = matches(phantom, one, 0);
  ASSERT_EQ(fiber_a.size(), 1u) << "the exported streamline is not exactly one fiber of the phantom";
  const Tractogram two = readAllStreamlines(*openTractogram(two_tck));
  ASSERT_EQ(two.streamlineCount(), 2u);
  EXPECT_TRUE(sameStreamline(two, 0, one, 0));  // in selection order: A first
  const std::vector<size_t> fiber_b = matches(phantom, two, 1);
  ASSERT_EQ(fiber_b.size(), 1u);
  EXPECT_NE(fiber_b[0], fiber_a[0]);

  // The selected fiber takes the highlight colour where it was picked.
  const Png selected = readOurPng(sel_png);
  ASSERT_EQ(selected.width, 320u);
  EXPECT_TRUE(highlightColoured(selected, a->first, a->second));
  size_t highlighted = 0;
  for (uint32_t y = 0; y < selected.height; ++y)
    for (uint32_t x = 0; x < selected.width; ++x) highlighted += highlightColoured(selected, x, y);
  EXPECT_GT(highlighted, 10u);
}

TEST_F(GpuViewer, failedSelectionExpectationIsAOneLineErrorNamingTheScriptLine) {
  const std::string script = dir_.file("expect.txt");
  test::writeBytes(script, "wait 1\npick 0 0\nexpect-selected 3\nquit\n");
  const auto r = runViewer("--offscreen --size 64x48 --script " + script);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(script + ":3: expect-selected 3: 0 fibers are selected"), std::string::npos) << r.output;
}

// --- loading on the worker (model_loader.h) ---------------------------------

TEST(ViewerScript, openAndWaitLoadedHoldUntilTheLoaderIsIdle) {
  ScriptRunner runner(parseScript("open a.tck\nwait-loaded\nview axial\nquit\n", "s"));
  const auto first = runner.nextFrame(/*loading=*/false);  // open is applied; the loader starts
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(std::get<OpenAction>(first[0]).path, "a.tck");
  EXPECT_TRUE(runner.nextFrame(true).empty());
  EXPECT_TRUE(runner.nextFrame(true).empty());
  EXPECT_FALSE(runner.finished());
  EXPECT_EQ(runner.nextFrame(false).size(), 2u);  // view, quit
  EXPECT_TRUE(runner.finished());
  EXPECT_THROW(parseScript("open\n", "s"), Error);
  EXPECT_THROW(parseScript("wait-loaded 3\n", "s"), Error);
}

TEST(ViewerRecentFiles, newestFirstWithoutDuplicatesAtMostTen) {
  std::vector<std::string> list;
  for (int i = 0; i < 12; ++i) list = addRecentFile(std::move(list), "/data/t" + std::to_string(i) + ".tck");
  list = addRecentFile(std::move(list), "/data/t5.tck");
  ASSERT_EQ(list.size(), kMaxRecentFiles);
  EXPECT_EQ(list[0], "/data/t5.tck");
  EXPECT_EQ(list[1], "/data/t11.tck");
  EXPECT_EQ(std::count(list.begin(), list.end(), "/data/t5.tck"), 1);
  EXPECT_EQ(addRecentFile(list, "").size(), kMaxRecentFiles);  // the phantom is not a file
  const auto relative = addRecentFile({}, "rel/x.tck");
  ASSERT_EQ(relative.size(), 1u);
  EXPECT_EQ(relative[0].front(), '/');
}

TEST(ViewerRecentFiles, savedListReadsBackAndMissingOrDamagedFilesAreHandled) {
  test::TempDir dir;
  const std::string a = dir.file("a.tck"), b = dir.file("b.tck"), json = dir.file("cache/recent_files.json");
  test::writeBytes(a, "x");
  test::writeBytes(b, "x");
  ASSERT_EQ(saveRecentFiles(json, {b, a, dir.file("gone.tck")}), "");
  EXPECT_EQ(loadRecentFiles(json), (std::vector<std::string>{b, a}));  // the missing one is dropped
  EXPECT_EQ(loadRecentFiles(json, /*drop_missing=*/false).size(), 3u);
  test::writeBytes(json, "{\"files\": [\"" + a + "\", 3, null");  // truncated
  EXPECT_TRUE(loadRecentFiles(json).empty());
  test::writeBytes(json, "{\"files\": [\"" + a + "\", 3]}");  // not a string: skipped
  EXPECT_EQ(loadRecentFiles(json), std::vector<std::string>{a});
  EXPECT_TRUE(loadRecentFiles(dir.file("none.json")).empty());
}

// A .tck whose header points past its end.
void writeMalformedTck(const std::string& path) {
  test::writeBytes(path, "mrtrix tracks\ncount: 5\ndatatype: Float32LE\nfile: . 200\nEND\n");
}

TEST_F(GpuViewer, scriptOpenOfAMalformedFileShowsTheErrorAndKeepsTheModel) {
  const std::string bad = dir_.file("bad.tck"), script = dir_.file("s.txt"), scene = dir_.file("scene.png");
  writeMalformedTck(bad);
  test::writeBytes(script, "open " + bad + "\nwait-loaded\nwait 2\nscreenshot " + scene + " 96x64\nwait 1\nquit\n");
  const auto r = runViewer("--offscreen --size 320x200 --script " + script);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fibscope view: " + bad + ": "), std::string::npos) << r.output;
  const Png png = readOurPng(scene);
  ASSERT_EQ(png.width, 96u);
  EXPECT_GT(coverage(png, 0, 0, 96, 64), 0.05);  // the phantom is still drawn
}

TEST_F(GpuViewer, commandLineFileThatCannotBeReadEndsAnOffscreenRunWithOneLine) {
  const std::string bad = dir_.file("bad.tck");
  writeMalformedTck(bad);
  const auto r = runViewer("--offscreen --size 64x64 --frames 2 " + bad);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(lineCount(r.output), 1) << r.output;
  EXPECT_NE(r.output.find(bad), std::string::npos) << r.output;
}

TEST_F(GpuViewer, commandLineFileThatCannotBeReadIsShownInTheWindowAndTheViewerGoesOn) {
  const std::string bad = dir_.file("bad.tck"), good = dir_.file("good.tck");
  writeMalformedTck(bad);
  ASSERT_EQ(test::runFibscope("phantom -n 200 " + good).exit_code, 0);
  const std::string script = dir_.file("s.txt"), shot = dir_.file("shot.png");
  test::writeBytes(script, "wait-loaded\nwait 1\nscreenshot " + shot + "\nwait 1\nquit\n");
  const auto r = runViewer("--size 320x200 --script " + script + " " + bad + " " + good,
                           "xvfb-run -a -s '-screen 0 640x480x24' env ");
  ASSERT_EQ(r.output.find("offscreen"), std::string::npos) << "no window was made: " << r.output;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fibscope view: " + bad + ": "), std::string::npos) << r.output;
  // The readable file is drawn beside the panels (the error in the status line).
  const Png png = readOurPng(shot);
  ASSERT_EQ(png.width, 320u);
  EXPECT_GT(coverage(png, 160, 60, 320, 200), 0.01);
}

TEST_F(GpuViewer, secondOpenOfTheSameFileComesFromTheCache) {
  const std::string tck = dir_.file("t.tck"), cache = dir_.file("cache");
  ASSERT_EQ(test::runCommand(std::string(FIBSCOPE_EXE) + " phantom -n 200 " + tck).exit_code, 0);
  const std::string png = dir_.file("x.png");
  const auto first = runViewer("--offscreen --size 320x200 --frames 1 --screenshot " + png + " " + tck, "", cache);
  ASSERT_EQ(first.exit_code, 0) << first.output;
  EXPECT_NE(first.output.find("opened t.tck compressed in "), std::string::npos) << first.output;
  const auto second = runViewer("--offscreen --size 320x200 --frames 1 --screenshot " + png + " " + tck, "", cache);
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_NE(second.output.find("opened t.tck from cache in "), std::string::npos) << second.output;
  // --frames counts once the file is in: the screenshot shows it.
  expectSceneAndPanels(readOurPng(png));
  // The recent files list next to the cache names it.
  EXPECT_EQ(loadRecentFiles(cache + "/recent_files.json"), std::vector<std::string>{tck});
}

TEST_F(GpuViewer, scriptLoadRunsOnTheWorkerWhileFramesGoOn) {
  const std::string tck = dir_.file("big.tck"), script = dir_.file("s.txt"), scene = dir_.file("scene.png");
  ASSERT_EQ(test::runCommand(std::string(FIBSCOPE_EXE) + " phantom -n 3000 " + tck).exit_code, 0);
  test::writeBytes(script, "open " + tck + "\nwait-loaded\nscreenshot " + scene + " 96x64\nwait 1\nquit\n");
  const auto r = runViewer("--offscreen --size 160x100 --script " + script);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const size_t at = r.output.find("opened big.tck compressed in ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const size_t comma = r.output.find(" in all, ", at);
  ASSERT_NE(comma, std::string::npos) << r.output;
  const int frames = std::atoi(r.output.c_str() + comma + 9);
  EXPECT_GE(frames, 2) << "frames drawn while the file was compressed: " << r.output;
  const Png png = readOurPng(scene);
  ASSERT_EQ(png.width, 96u);
  EXPECT_GT(coverage(png, 0, 0, 96, 64), 0.05);
}

// --- several models (issue 5, item 3): every visible model in one frame ----

class GpuMultiModelViewer : public GpuViewer {};

// A phantom compressed to a .fbl (opened as stored: its decode is the
// reference the export is compared with): the named bundles alone, whose
// gaps leave pixels where one model shows without the other (the
// whole-brain mix covers nearly the whole view with either).
Tractogram compressPhantom(const std::string& fbl, uint64_t seed) {
  CompressOptions options;
  options.terminal_progress = false;
  options.threads = 1;
  compressTractogram(
      [seed] {
        PhantomOptions p;
        applyNamedBundlesPhantomMix(p);
        p.streamlines = 300;
        p.seed = seed;
        p.threads = 1;
        return openPhantom(p);
      },
      fbl, options);
  return readAllStreamlines(*openFbl(fbl));
}

TEST_F(GpuMultiModelViewer, twoModelsAreDrawnTogetherHiddenAndPickedByModel) {
  // Two phantoms of different seeds: the same brain-like shape, different
  // fibers, overlapping everywhere.
  const std::string fbl_a = dir_.file("a.fbl"), fbl_b = dir_.file("b.fbl");
  const Tractogram fibers_a = compressPhantom(fbl_a, 3), fibers_b = compressPhantom(fbl_b, 8);

  // The scene with A alone (B hidden), B alone, and both: same camera,
  // framed on both by the reset key once both are in (adding B keeps the
  // view A's loading framed, and whether they come in one frame or two
  // depends on the machine's speed), not when one is hidden.
  const std::string look = dir_.file("look.txt");
  const std::string png_a = dir_.file("a.png"), png_b = dir_.file("b.png"), png_both = dir_.file("both.png");
  test::writeBytes(look, "wait-loaded\nview reset\nwait 2\nmodel 1 hide\nwait 1\nscreenshot " + png_a +
                             " 320x200\nmodel 1 show\nmodel 0 hide\nwait 1\nscreenshot " + png_b +
                             " 320x200\nmodel 0 show\nwait 1\nscreenshot " + png_both + " 320x200\nquit\n");
  auto r = runViewer("--offscreen --size 320x200 --script " + look + " " + fbl_a + " " + fbl_b);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Png a = readOurPng(png_a), b = readOurPng(png_b), both = readOurPng(png_both);
  ASSERT_EQ(both.width, 320u);
  const double cover_a = coverage(a, 0, 0, 320, 200), cover_b = coverage(b, 0, 0, 320, 200);
  const double cover_both = coverage(both, 0, 0, 320, 200);
  std::printf("covered: A %.3f, B %.3f, both %.3f\n", cover_a, cover_b, cover_both);
  EXPECT_GT(cover_a, 0.05);
  EXPECT_GT(cover_b, 0.05);
  EXPECT_GT(cover_both, std::max(cover_a, cover_b) + 0.01) << "both models are drawn";
  EXPECT_LE(cover_both, cover_a + cover_b + 0.005);

  // P: covered (3x3) with both shown and with B alone, nothing of A within
  // 3 px: B's fiber wins there. Q likewise for A.
  auto block = [](const Png& png, uint32_t x, uint32_t y, int radius, bool want) {
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx)
        if (covered(png, uint32_t(int(x) + dx), uint32_t(int(y) + dy)) != want) return false;
    return true;
  };
  std::optional<std::pair<uint32_t, uint32_t>> p, q;
  for (uint32_t y = 4; y + 4 < 200; ++y)
    for (uint32_t x = 4; x + 4 < 320; ++x) {
      if (!p && block(both, x, y, 1, true) && block(b, x, y, 1, true) && block(a, x, y, 3, false)) p = {x, y};
      if (!q && block(both, x, y, 1, true) && block(a, x, y, 1, true) && block(b, x, y, 3, false)) q = {x, y};
    }
  ASSERT_TRUE(p && q) << "no pixel of one model alone";
  auto at = [](const std::pair<uint32_t, uint32_t>& v) {
    return std::to_string(v.first) + " " + std::to_string(v.second);
  };

  // Pick B's fiber at P, add A's at Q; export with A active writes A's
  // fiber only, with B active B's; hide B and P is background.
  const std::string pick = dir_.file("pick.txt"), sel_png = dir_.file("sel.png");
  const std::string tck_b = dir_.file("b.tck"), tck_a = dir_.file("a.tck"), tck_last = dir_.file("last.tck");
  // The same framing (a sized screenshot ends the reset's animation).
  test::writeBytes(pick, "wait-loaded\nview reset\nscreenshot " + dir_.file("settle.png") + " 32x20\nwait 2\n"
                         "pick " + at(*p) + "\n"
                         "expect-selected 1\n"
                         "model 0 activate\n"  // A has no selected fiber: the export writes B's
                         "export-selection " + tck_last + "\n"
                         "screenshot " + sel_png + " 320x200\n"
                         "pick " + at(*q) + " add\n"
                         "expect-selected 2\n"
                         "export-selection " + tck_a + "\n"
                         "model 1 activate\n"
                         "export-selection " + tck_b + "\n"
                         "model 1 hide\n"
                         "wait 1\n"
                         "pick " + at(*p) + "\n"  // nothing drawn there now: clears the selection
                         "expect-selected 0\n"
                         "wait 1\n"
                         "quit\n");
  r = runViewer("--offscreen --size 320x200 --script " + pick + " " + fbl_a + " " + fbl_b);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const Tractogram last = readAllStreamlines(*openTractogram(tck_last));
  ASSERT_EQ(last.streamlineCount(), 1u);
  EXPECT_EQ(matches(fibers_b, last, 0).size(), 1u) << "the fiber picked at P is one of B's";
  EXPECT_TRUE(matches(fibers_a, last, 0).empty());
  const Tractogram only_a = readAllStreamlines(*openTractogram(tck_a));
  ASSERT_EQ(only_a.streamlineCount(), 1u) << "one model per file";
  EXPECT_EQ(matches(fibers_a, only_a, 0).size(), 1u) << "the fiber picked at Q is one of A's";
  const Tractogram only_b = readAllStreamlines(*openTractogram(tck_b));
  ASSERT_EQ(only_b.streamlineCount(), 1u);
  EXPECT_TRUE(sameStreamline(only_b, 0, last, 0));

  // The highlight is on B's fiber at P, in the frame that draws both.
  const Png selected = readOurPng(sel_png);
  ASSERT_EQ(selected.width, 320u);
  // (Near P: the lit fiber's specular peak saturates towards white.)
  size_t near_p = 0, highlighted = 0;
  for (uint32_t y = 0; y < selected.height; ++y)
    for (uint32_t x = 0; x < selected.width; ++x) {
      const bool h = highlightColoured(selected, x, y);
      highlighted += h;
      near_p += h && std::abs(int(x) - int(p->first)) <= 3 && std::abs(int(y) - int(p->second)) <= 3;
    }
  EXPECT_GT(near_p, 0u) << "the fiber picked at P is highlighted";
  EXPECT_GT(highlighted, 10u);
}

}  // namespace
}  // namespace fibscope
