// The plain state the viewer's panels edit and read (STYLE.md rule 10): the
// render settings, the list of models, the frame statistics history and UI
// flags. No Vulkan, no ImGui: the frame loop owns the GPU objects and fills
// the statistics; viewer_ui only reads and writes this.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/dissection.h"
#include "bundling/bundle_params.h"
#include "core/progress.h"
#include "render/camera.h"
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
  // Statistics of the loaded .fbl (ModelData), for the models panel.
  uint64_t points = 0;
  double step_mm = 0;
  uint64_t input_bytes = 0, fbl_bytes = 0;  // input 0: unknown (phantom)
  bool from_cache = false;                   // no compression ran
  double compress_seconds = 0;               // 0 when from_cache
  double mean_error_um = 0, max_error_um = 0;  // codec error when compressed now
};

// A load that failed (from the UI or a script): shown in the models panel
// until dismissed; the message is one line naming the file.
struct LoadFailure {
  std::string path;
  std::string message;
};

// The running load job, for the progress bar (viewer_ui_models.cpp).
struct LoadingInfo {
  std::string path;   // "" = the built-in phantom
  std::string label;  // the phase: "checking the cache", "compressing", ...
  double done = 0, total = 0;  // total 0: unknown
  double rate = 0;             // units per second
  std::string unit;            // "points", "bytes", ...
  double eta_seconds = -1;     // -1: unknown
  double elapsed_seconds = 0;
  size_t queued = 0;  // further jobs waiting behind this one
};

// The Bundle panel (viewer_ui_bundling.cpp): its parameters, the running
// job's progress, and the last source and bundled copy (indices into
// ViewerState::models, -1: none).
struct BundlingInfo {
  BundleParams params;  // the paper's defaults
  bool running = false;  // bundling or loading the copy
  LoadingInfo progress;
  int source_model = -1, bundled_model = -1;
  std::string message;  // the last result or error
  std::string save_path = "bundled.tck";
};

// The split view (split_view.h): model `left` in the window's left half,
// `right` in the right half, from one camera. While it is on, picking and
// the dissection's filter are off (each half is a scene of its own
// numbering); cuts, anatomy and every render setting apply to both.
struct SplitViewInfo {
  bool on = false;
  int left = -1, right = -1;  // indices into models
};

// One frame's numbers, kept for the performance overlay's history.
struct FrameRecord {
  double frame_ms = 0;  // wall time between frame starts (CPU side)
  FrameStats gpu;       // passes, GPU time, fiblets drawn
};

// The fiber selection (fibers of any model), for the selection panel
// (viewer_ui_selection.cpp); the frame loop fills it from its
// ViewerSelection after each change.
struct SelectedFiber {
  std::string model;               // the model's name
  uint32_t fiber = 0;              // streamline index in the model
  std::optional<float> length_mm;  // nullopt: no length in reach
};
struct SelectionInfo {
  std::vector<SelectedFiber> fibers;  // in selection order
  bool exportable = false;            // a selected model's .fbl is in reach
  std::string export_path = "selection.tck";
};

// The anatomical volume shown as slices (viewer_anatomy.h fills it), for
// the anatomy panel (viewer_ui_anatomy.cpp) and the slice keys.
struct AnatomyInfo {
  std::string path;  // empty: none loaded
  int dims[3] = {0, 0, 0};
  double voxel_mm[3] = {0, 0, 0};
  float min = 0, max = 0;                // of its finite values
  float robust_min = 0, robust_max = 1;  // the default display range
  bool loaded() const { return !path.empty(); }
};

// Spline tubes (issue 15 item 5; viewer_tubes.h builds them, the tubes
// panel viewer_ui_tubes.cpp edits this): which fibers are drawn as tubes
// over the lines, their radius and resampling tolerance, and the last
// build. The method, rings, vertices and MSAA are settings (group "tubes").
struct TubesInfo {
  bool selection = false;  // the picked selection as tubes
  bool filtered = false;   // the dissection's kept fibers as tubes (with the selection's, when both)
  bool all = false;        // every fiber of the visible models (then the two above add nothing)
  // SVO streamtubes (issue 16 item 5): the same fibers drawn from a sparse
  // voxel octree (svo/gpu/gpu_svo.h) instead of the spline tubes: straight
  // capsules (svo-straight) or curved tubes (svo-curved); `voxel_mm` the
  // octree's voxel, 0: chosen from the data (chooseSvoGrid). The octree is
  // built from the fibers' own points (tolerance 0, as render's
  // --pipeline svo-*), so `tolerance_mm` is the spline tubes' only.
  enum class Svo { None, Straight, Curved };
  Svo svo = Svo::None;
  float voxel_mm = 0.0f;
  // The octree trace's level of detail (SvoTraceOptions::lod_px): a node
  // smaller than this many pixels stops the ray, hit by its representative
  // segment; 0: the exact walk. Read at every frame (no rebuild).
  float svo_lod_px = 0.0f;
  float radius_mm = 0.5f;
  // The radius from an array of the models instead: per fiber (a .fbl
  // "dps/NAME" section: trk properties, TRX dps), else per point ("dpv/NAME":
  // trk scalars, TRX dpv), its values' range mapped linearly onto
  // [radius_min, radius_max] mm; empty: radius_mm.
  std::string radius_from;
  float radius_min = 0.2f, radius_max = 1.0f;
  float tolerance_mm = 0.025f;  // resampling (TubeBuildOptions::resample_tolerance)
  // The last build (the frame loop fills these).
  bool building = false;
  uint64_t fibers = 0, nodes = 0, points = 0, segments = 0, bytes = 0;
  double build_seconds = 0;
  std::string message;  // why there are none, or what failed
  // The octree of the last build (svo != None), and the running build's
  // phase ("tube model", "voxelising", "sorting", "building", "distance
  // field") with its rate and ETA.
  uint64_t svo_leaves = 0, svo_nodes_bytes = 0, svo_decoration_bytes = 0;
  uint32_t svo_side = 0;
  float svo_voxel = 0;
  bool svo_from_cache = false;
  bool svo_kept = false;   // the last build kept the octree drawn before (only the field was new)
  double svo_seconds = 0;  // voxelise + sort + build, or the cache's read
  // The tubes' distance field (for DF AO / DF shadows, when the settings ask).
  uint64_t df_bytes = 0;
  float df_voxel = 0;
  double df_seconds = 0;
  std::optional<ProgressSnapshot> progress;
  bool wanted() const { return selection || filtered || all; }
};

struct ViewerState {
  RenderSettings settings;
  double fov_deg = 30;
  // Adaptive detail: where a full frame takes over 100 ms, frames drawn while
  // the camera moves use the far-view LoD below moving_lod_px (fiblets as
  // one segment); the full detail returns when the camera stops.
  bool adaptive_detail = true;
  float moving_lod_px = 160.0f;
  bool coarse_frame = false;  // the last frame shown was such a coarse one
  // The active model's per-fiber scalar (fiber length, mm) range, for the
  // scalar colour mode's "fit" button; min > max while unknown.
  float scalar_data_min = 1, scalar_data_max = 0;

  std::vector<ModelInfo> models;
  int active_model = -1;  // index into models, -1: none
  // Loading (the frame loop fills these from its ModelLoader).
  std::vector<LoadingInfo> loading;  // the running job first; empty when idle
  std::vector<LoadFailure> load_failures;
  std::vector<std::string> recent_files;  // newest first (recent_files.h)
  SelectionInfo selection;
  // The virtual dissection (dissection.h): ROIs, cuts, the kept count.
  DissectionState dissection;
  // The camera of the last frame drawn (the window's size) and the box of
  // every loaded model: the dissection panel places ROIs and clip planes
  // at the focal point and draws the ROIs' outlines with them.
  Camera camera;
  Bounds scene_bounds;
  AnatomyInfo anatomy;
  std::string anatomy_path;  // the anatomy panel's path entry
  // Every visible model is drawn; with a baseline pipeline (lines,
  // raw-compute: one tractogram) only the active one, which the status of
  // the settings panel then says.
  bool baseline_draws_active_only = false;

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

  BundlingInfo bundling;
  SplitViewInfo split;
  TubesInfo tubes;

  // UI flags.
  bool show_settings = true;
  bool show_performance = true;
  bool show_models = true;
  bool show_selection = true;
  // Opened by the frame loop when the dissection gets its first ROI or
  // plane (as the selection panel appears with a selection).
  bool show_dissection = false;
  bool show_anatomy = true;
  bool show_bundling = true;
  bool show_tubes = false;
  std::string screenshot_path = "fibscope.png";  // the screenshot button's file
  std::string open_path;                         // the models panel's path entry
  int screenshot_width = 0, screenshot_height = 0;  // 0: the window as shown
};

}  // namespace fibscope
