// The viewer's virtual dissection as plain state (STYLE.md rule 10): the
// ROIs, ends-only, length limits and clip planes of a ROI set
// (select/roi_set.h), what the panel and the mouse edit, and the edits the
// scripts make. No Vulkan, no ImGui: viewer_dissection.h evaluates the
// criteria on the GPU, viewer_ui_dissection.cpp draws the panel.
//
// One owner per value: the slab's thickness is RenderSettings::slab_mm
// (the settings panel and `set slab` edit it too); the state keeps the
// set's slab "follow" word and its anatomy (not drawn by the viewer yet)
// only so that a saved set says what the loaded one said. The set's cut
// meshes are drawn: viewer_cuts.h uploads them.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>

#include <glm/vec3.hpp>

#include "render/anatomy_slices.h"
#include "render/camera.h"
#include "render/render_settings.h"
#include "select/roi_set.h"
#include "shared/cut_mesh.h"

namespace fibscope {

// What the frame loop measured for the state's criteria (read by the panel).
struct DissectionStats {
  bool active = false;            // some criterion is set (else every fiber is kept)
  bool evaluated = false;         // kept / fibers are those of the current criteria and scene
  uint64_t kept = 0, fibers = 0;  // of the scene drawn (every visible model, or a baseline's one)
  double update_ms = 0;           // wall time of the last GPU update (submission to result)
  std::string error;              // criteria the GPU filter refused (everything is drawn then)
  // The per-streamline arrays of the models drawn (each name once, with
  // the most components a model has), for the panel's scalar ranges, and
  // each component's smallest and largest finite value over the scene
  // (lo > hi: none). A fiber of a model without a range's array has a
  // NaN value: the range drops it.
  struct ScalarArray {
    std::string name;
    uint32_t components = 1;
    std::vector<float> lo, hi;  // per component
  };
  std::vector<ScalarArray> scalar_arrays;
};

struct DissectionState {
  RoiSet set;                // its slab: see above (thickness_mm is not read)
  int selected = -1;         // the ROI the mouse moves and resizes (index into set.rois), -1: none
  bool dim_dropped = false;  // dropped fibers drawn dimmed (the kept ones as the selection) instead of hidden
  DissectionStats stats;
  // The panel's file fields and the last save / load / export outcome.
  std::string roi_set_path = "dissection.json";
  std::string export_path = "kept.tck";
  std::string file_message;  // one line: "saved ...", or the error of a load that failed
  bool exporting = false;    // an export runs (the frame loop sets it)
  // The panel's mesh cut field and the last add's error (one line).
  std::string cut_mesh_spec;
  std::string cut_mesh_message;
  // Per cut mesh spec (viewer_cuts.h fills it between frames): its closure
  // warning (the cut may be approximate) or why it is not drawn; absent or
  // "" when it is drawn as given.
  std::map<std::string, std::string> cut_mesh_notes;
};

// --- edits (scripts; the panel edits the state directly) ------------------

struct RoiAddEdit {
  std::string name;
  RoiRole role = RoiRole::Include;
  Region region;
};
struct RoiRemoveEdit {
  std::string name;  // "": the selected ROI
};
struct RoiEnableEdit {
  std::string name;
  bool enabled = true;
};
struct EndsOnlyEdit {
  bool on = false;
};
struct LengthEdit {
  double min_mm = NAN, max_mm = NAN;  // NaN: no limit
};
struct ClipPlaneAddEdit {
  ClipPlane plane;
};
struct ClipPlaneClearEdit {};
struct SlabEdit {
  float thickness_mm = 0;  // 0: no slab
};
struct DroppedEdit {
  bool dim = false;
};
// A closed mesh cut (select/cuts.h's MeshCut), enabled. ViewerApp reads
// and uploads its mesh before the edit is applied, so a spec whose file
// cannot be read changes nothing.
struct CutMeshAddEdit {
  MeshCut cut;
};
struct CutMeshClearEdit {};
// A per-fiber scalar range, enabled: it replaces the set's range on the
// same array and component, or is added after the others.
struct FiberScalarEdit {
  ScalarRange range;
};
struct FiberScalarClearEdit {};
using DissectionEdit = std::variant<RoiAddEdit, RoiRemoveEdit, RoiEnableEdit, EndsOnlyEdit, LengthEdit,
                                    ClipPlaneAddEdit, ClipPlaneClearEdit, SlabEdit, DroppedEdit, CutMeshAddEdit,
                                    CutMeshClearEdit, FiberScalarEdit, FiberScalarClearEdit>;

// Applies `edit` to the state (and, for the slab, to `settings`). Throws
// Error (one line) and changes nothing for: a ROI name already used
// (RoiAddEdit) or not found, no ROI selected for RoiRemoveEdit without a
// name, a min length above the max or a negative one, a clip plane beyond
// kMaxClipPlanes enabled ones, a cut mesh beyond kMaxCutMeshes enabled
// ones, a negative or non-finite slab, a scalar range whose min is above
// its max or beyond FiberFilter::kMaxScalarRanges enabled ones.
void applyDissectionEdit(DissectionState& state, RenderSettings& settings, const DissectionEdit& edit);

// The first ROI named `name`, or -1.
int findRoi(const RoiSet& set, const std::string& name);
// `base` followed by the first "-N" (N = 1, 2, ...) no ROI is named yet.
std::string uniqueRoiName(const RoiSet& set, const std::string& base);
// The set's scalar range on this array and component, or -1.
int findScalarRange(const RoiSet& set, const std::string& name, uint32_t component);
size_t enabledScalarRanges(const RoiSet& set);
// Enabled clip planes and cut meshes of the set.
size_t enabledClipPlanes(const RoiSet& set);
size_t enabledCutMeshes(const RoiSet& set);
// The cut meshes drawn at once (the cut stage's slots).
inline constexpr size_t kMaxCutMeshes = shader::kMaxCutMeshes;

// --- what the frame draws -------------------------------------------------

// The fiber filter's criteria (roi_set.h's filterCriteria: enabled ROIs,
// ends-only, lengths, enabled scalar ranges).
FilterCriteria dissectionCriteria(const DissectionState& state);
// Appends the set's enabled clip planes to settings.clip_planes as world
// (n, d) planes (render/clip_planes.h's planeThrough), as many as fit in
// kMaxClipPlanes with those already there. Returns how many did not fit.
size_t addDissectionCuts(const RoiSet& set, RenderSettings& settings);

// --- ROI sets on disk -----------------------------------------------------

// The set to save: the state's, with the slab of `settings` (thickness
// slab_mm when > 0; following the view of the active slice, "axial" ...,
// when slab_follows_slice, by the axes of `grid`: the anatomy shown, null
// for none, taken as RAS-ordered).
RoiSet roiSetToSave(const DissectionState& state, const RenderSettings& settings,
                    const AnatomyGrid* grid = nullptr);
// Makes `set` the state (selection cleared) and its slab the settings'
// slab_mm (0 without one), a slab that follows a view the active slice of
// that view (by `grid`'s axes, as above) with slab_follows_slice. Throws
// Error (state unchanged) for more than kMaxClipPlanes enabled planes or
// kMaxCutMeshes enabled cut meshes.
void loadRoiSetIntoState(RoiSet set, DissectionState& state, RenderSettings& settings,
                         const AnatomyGrid* grid = nullptr);
// The world (n, d) planes of the command line (RenderSettings::clip_planes)
// as the set's clip planes (point = -d n, the point of the plane nearest
// the origin), for the viewer to own them.
std::vector<RoiClipPlane> clipPlanesFromSettings(const std::vector<std::array<double, 4>>& planes);

// --- placing and moving ROIs (the panel's buttons, the mouse) ---------------

// A radius that reads as a ROI in a scene of these bounds: 3 % of its
// diagonal (7.5 mm in a brain), at least 0.5 mm.
double defaultRoiRadius(const Bounds& scene);
SphereRegion sphereAt(const glm::dvec3& center, double radius);
// An axis-aligned cube of this half size about `center`.
BoxRegion boxAt(const glm::dvec3& center, double half_size);
// The half size (or radius) of the panel's built-in cut meshes: a cut
// hides a part of the scene, so larger than a ROI: 15 % of the diagonal
// (about 37 mm in a brain), at least 1 mm.
double defaultCutSize(const Bounds& scene);
// The centre of a sphere or box (an oriented box's centre); nullopt for a
// mask (not moved by the mouse).
std::optional<glm::dvec3> regionCenter(const Region& region);
// The region moved by `delta` (mm); a mask comes back unchanged.
Region movedRegion(const Region& region, const glm::dvec3& delta);
// The region scaled by `factor` > 0 about its centre (radius, sizes); a
// mask comes back unchanged.
Region scaledRegion(const Region& region, double factor);
// An oriented box from its panel fields (centre, full sizes, angles in
// degrees), its axes computed as parseRegion computes them. Throws Error
// for a size <= 0 or a non-finite value.
OrientedBoxRegion orientedBox(const glm::dvec3& center, const glm::dvec3& size, const glm::dvec3& angles_deg);

// The plane through the camera's target facing the eye (its normal towards
// the eye: it keeps the viewer's side of the focal plane).
ClipPlane planeFacingViewer(const Camera& camera);
// The world displacement that moves a point at `at` by (dx, dy) window
// pixels (y down) in the plane through it facing the viewer: the point
// follows the cursor exactly (perspective at its depth).
glm::dvec3 viewPlaneDrag(const Camera& camera, const glm::dvec3& at, double dx_px, double dy_px);

}  // namespace fibscope
