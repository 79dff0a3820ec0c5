// What the viewer can be asked to do, whoever asks: mouse and keys
// (viewer_input), the panels (viewer_ui) and scripts (viewer_script) all
// produce these, and ViewerApp::apply is the one place that carries them
// out. Adding a command: an alternative here, its parse in viewer_script.cpp,
// its case in ViewerApp::apply.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "app/viewer/dissection.h"
#include "bundling/bundle_params.h"
#include "render/camera.h"
#include "render/render_settings.h"

namespace fibscope {

struct OrbitAction {  // left drag, window pixels (y down)
  double dx = 0, dy = 0;
};
struct PanAction {  // middle or shift-left drag, window pixels (y down)
  double dx = 0, dy = 0;
};
struct DollyAction {  // wheel steps, + = towards the scene
  double steps = 0;
};
struct ViewAction {  // a standard view, or (none) the reset view
  std::optional<StandardView> view;
};
struct FovAction {
  double degrees = 30;
};
struct SetAction {  // a RenderSettings field by its script name (applySetting)
  std::string key, value;
};
struct ScreenshotAction {
  std::string path;                // .png
  uint32_t width = 0, height = 0;  // 0: the window as shown, panels included; else the scene alone at this size
};
struct OpenAction {  // a tractogram file to add to the model list (empty: the built-in phantom)
  std::string path;
};
struct CloseModelAction {  // removes a model from the list (index into ViewerState::models)
  int model = -1;
};
// Every visible model is drawn; the active one is the one whose statistics
// the models panel shows (and whose raw vertices the baselines draw).
struct ModelAction {  // index into ViewerState::models
  enum class Op : uint8_t { Show, Hide, Activate };
  int model = -1;
  Op op = Op::Show;
};
// Picking (left click / ctrl + left click, or a script's `pick`): the fiber
// drawn at window pixel (x, y) of the last frame (y down). A plain pick
// makes the selection that fiber (the background clears it); `add` toggles
// the fiber in the selection.
struct PickAction {
  double x = 0, y = 0;
  bool add = false;
};
struct ClearSelectionAction {};
struct ExportSelectionAction {  // the selected fibers to a .tck
  std::string path;
};
// A script's check: the run fails (Error "`where`: ...") unless exactly
// `count` fibers are selected.
struct ExpectSelectedAction {
  uint64_t count = 0;
  std::string where;  // "SCRIPT:LINE"
};
// The virtual dissection (dissection.h): a script's change of its state
// (the panel edits the state itself).
struct DissectionAction {
  DissectionEdit edit;
};
// roi-save / roi-load: the state as a ROI set file (select/roi_set.h). A
// load that fails leaves the state as it was and shows the one-line error.
struct RoiSetFileAction {
  bool save = true;
  std::string path;
};
// The kept fibers of the active model's source file, streamed through the
// filter as `fibscope filter` does (viewer_dissection.h), on a thread.
struct ExportKeptAction {
  std::string path;
};
// A script's check: the run fails (Error "`where`: ...") unless the filter,
// evaluated now, keeps exactly `count` fibers of the scene drawn.
struct ExpectKeptAction {
  uint64_t count = 0;
  std::string where;  // "SCRIPT:LINE"
};
// The mouse on ROIs (viewer_input.h): a sphere placed at the point drawn at
// window pixel (x, y) (on the focal plane where nothing is drawn); the
// selected ROI dragged by window pixels in the view plane, or resized by
// wheel steps (each x or / 1.1).
struct RoiPlaceAction {
  double x = 0, y = 0;
};
struct RoiDragAction {
  double dx = 0, dy = 0;
};
struct RoiResizeAction {
  double steps = 0;
};
struct ResizeAction {  // the window (or the offscreen image) to this size in pixels
  uint32_t width = 0, height = 0;
};
struct QuitAction {};
// An anatomical image (.nii, .nii.gz) shown as slices, replacing the one
// shown (viewer_anatomy.h); an empty path removes it.
struct AnatomyAction {
  std::string path;
};
// Which fibers the viewer draws as spline tubes (TubesInfo; viewer_tubes.h):
// the selection's, the dissection's kept ones, both or none; radius_mm
// > 0 also sets the radius, radius_from the per-fiber array the radius
// comes from ("": the constant radius), radius_min > 0 its range.
// all: every fiber of the visible models. svo (TubesInfo::Svo: 0 none, 1
// straight, 2 curved) and voxel_mm (>= 0, 0: from the data) set how they
// are drawn when given, svo_lod_px the octree trace's level of detail.
struct TubesAction {
  bool selection = false, filtered = false, all = false;
  std::optional<int> svo;
  std::optional<float> voxel_mm;
  std::optional<float> svo_lod_px;
  float radius_mm = 0;
  std::optional<std::string> radius_from;
  float radius_min = 0, radius_max = 0;
};
// Moves the active slice (RenderSettings::active_slice) by this many
// voxels, within the volume (Page Up / Page Down).
struct SliceStepAction {
  double voxels = 0;
};

// Bundling (viewer_bundling.h): the active model bundled on a worker with
// these parameters; the copy is added as a new model, shown and active, the
// source hidden. Cancel stops a running job.
struct BundleAction {
  BundleParams params;
};
struct CancelBundleAction {};
// Model N shown and active, every other model hidden (the Bundle panel's
// original / bundled toggle).
struct ShowOnlyModelAction {
  int model = -1;
};
// The split view (viewer_state.h SplitViewInfo): on with models LEFT and
// RIGHT side by side, or off (the models' own visibility again).
struct SplitViewAction {
  bool on = false;
  int left = -1, right = -1;
};
// Model N's fibers written by PATH's extension as `fibscope bundle` writes
// (app/bundle_output.h): its source file read again (a bundled copy's is its
// exact positions), else its .fbl, else the phantom. An existing PATH is refused.
struct SaveModelAction {
  int model = -1;
  std::string path;
};

using ViewerAction = std::variant<OrbitAction, PanAction, DollyAction, ViewAction, FovAction, SetAction,
                                  ScreenshotAction, OpenAction, CloseModelAction, ModelAction, PickAction, ClearSelectionAction,
                                  ExportSelectionAction, ExpectSelectedAction, DissectionAction, RoiSetFileAction,
                                  ExportKeptAction, ExpectKeptAction, RoiPlaceAction, RoiDragAction, RoiResizeAction,
                                  ResizeAction, QuitAction, AnatomyAction, SliceStepAction, BundleAction,
                                  CancelBundleAction, ShowOnlyModelAction, SplitViewAction, SaveModelAction, TubesAction>;

// Sets one RenderSettings field from text, as `set KEY VALUE` in a script:
// KEY is a setting's name in render/settings_table.h (the command line's
// --KEY without the dashes; `width` still names line-width), VALUE as on the
// command line, `on`/`off` for flags. Throws Error (one line) naming the
// key and what was expected; leaves `settings` unchanged then. Safe on
// untrusted text.
void applySetting(RenderSettings& settings, std::string_view key, std::string_view value);

// "sagittal" -> Sagittal ...; "reset" -> a ViewAction without a view.
// Throws Error listing the names.
ViewAction parseViewName(std::string_view name);

}  // namespace fibscope
