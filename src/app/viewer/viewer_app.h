// `fibscope view`: the frame loop. Each frame: window events and script
// commands become actions (viewer_input, viewer_script) -> the orbit
// controller -> FrameRenderer::record -> the colour buffer copied into the
// presentation image -> the ImGui pass on it -> blit to the swapchain image
// -> present. One frame in flight (a fence). Offscreen (no display, or
// --offscreen) the same loop runs without window and swapchain.
#pragma once

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "render/render_settings.h"
#include "select/roi_set.h"

namespace fibscope {

struct ViewerOptions {
  std::vector<std::string> files;  // none: the built-in phantom
  uint64_t phantom_streamlines = 10000;
  uint32_t width = 1280, height = 800;
  std::string screenshot;  // written after the last frame (the presentation image, panels included)
  uint32_t frames = 0;     // > 0: stop after this many frames (and the script)
  std::string script;      // viewer_script.h
  bool offscreen = false;  // no window even when there is a display
  bool vsync = true;       // false: mailbox or immediate presentation where available
  // Degrees per frame the camera turns about the view's up axis (0: still):
  // a benchmark session like `fibscope bench`'s orbit, through the whole
  // viewer frame loop (panels, presentation). With it, a summary of the
  // frame times is printed at exit.
  double orbit_deg_per_frame = 0;
  // settings' scalar range was given (--scalar-range): kept, where otherwise
  // each model shown sets it to its fibers' lengths.
  bool keep_scalar_range = false;
  // The dissection to start with (--roi-set, --include ...: cmd_view.cpp);
  // settings.clip_planes join its planes.
  RoiSet dissection;
  bool dim_dropped = false;
  // An anatomical image shown as slices from the start (--anatomy), with
  // the settings the command line gave (kept for it: slice positions and
  // display range), by their names in render/settings_table.h.
  std::string anatomy;
  std::set<std::string, std::less<>> given_settings;
  bool validate = false;   // validation layers on; any message fails the run
  std::string device;
  RenderSettings settings;
};

// Runs the viewer until the window is closed, the script quits, or the
// frames are done. Throws Error (one line) for a malformed script, unusable
// Vulkan, a model that cannot be read at start, or validation messages with
// `validate`.
void runViewer(const ViewerOptions& options);

}  // namespace fibscope
