// The plain state the viewer's panels edit and read (STYLE.md rule 10): the
// render settings, the list of models, the frame statistics history and UI
// flags. No Vulkan, no ImGui: the frame loop owns the GPU objects and fills
// the statistics; viewer_ui only reads and writes this.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "render/render_settings.h"

namespace fibscope {

// One model in the list (its GPU data lives with the frame loop, at the
// same index).
struct ModelInfo {
  std::string name;  // file name, or "phantom"
  std::string path;  // empty: the built-in phantom
  bool visible = true;
  uint64_t streamlines = 0, segments = 0, fiblets = 0;
  double load_seconds = 0;
};

// One frame's numbers, kept for the performance overlay's history.
struct FrameRecord {
  double frame_ms = 0;  // wall time between frame starts (CPU side)
  FrameStats gpu;       // passes, GPU time, fiblets drawn
};

struct ViewerState {
  RenderSettings settings;
  double fov_deg = 30;

  std::vector<ModelInfo> models;
  int active_model = -1;  // index into models, -1: none

  // Newest last, at most kFrameHistory.
  static constexpr size_t kFrameHistory = 240;
  std::deque<FrameRecord> frames;
  void addFrame(FrameRecord record) {
    frames.push_back(std::move(record));
    while (frames.size() > kFrameHistory) frames.pop_front();
  }

  // Shown in the status line: the last error (a failed screenshot, a model
  // that could not be read) or what just happened.
  std::string status;

  // UI flags.
  bool show_settings = true;
  bool show_performance = true;
  bool show_models = true;
  std::string screenshot_path = "fibscope.png";  // the screenshot button's file
  int screenshot_width = 0, screenshot_height = 0;  // 0: the window as shown
};

}  // namespace fibscope
