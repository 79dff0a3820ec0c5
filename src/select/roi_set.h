// A ROI set: the whole state of a virtual dissection in one JSON file (the
// regions and their roles, the length limits, the cuts, the anatomy shown),
// read by `fibscope filter --roi-set` and, later, saved and opened by the
// viewer.
//
// Schema, version 1 (every key optional except the version; within an
// entry, the keys marked required):
//   { "fibscope_roi_set": 1,
//     "rois": [ { "name": "CST upper",                 // default ""
//                 "region": "sphere:1,2,3,4",          // required: region.h's spec
//                 "role": "include" | "exclude" | "include_ordered",  // default "include"
//                 "enabled": true } ],                 // default true
//     "ends_only": false,
//     "min_length_mm": 20, "max_length_mm": 250,       // numbers >= 0; absent: no limit
//     "scalar_ranges": [ { "name": "fa_mean",          // required: a per-streamline array
//                          "component": 0,             // default 0
//                          "min": 0.3, "max": 0.9,     // numbers, min <= max; absent: open
//                          "enabled": true } ],        // at most kFilterMaxScalarRanges enabled
//     "clip_planes": [ { "point": [x, y, z], "normal": [x, y, z],   // required; normal non-zero
//                        "enabled": true } ],          // at most kMaxClipPlanes enabled
//     "slab": { "thickness_mm": 5,                     // required, > 0
//               "follow": "axial" },                   // "", "axial", "coronal", "sagittal"; default ""
//     "cut_meshes": [ { "mesh": "cut.obj" | "box:..." | "obox:..." | "sphere:...",  // required
//                       "cull": "inside" | "outside",  // required
//                       "enabled": true } ],
//     "anatomy": "t1.nii.gz" }
// ROIs of role include_ordered are entered in the order they are listed.
// Clip planes keep dot(p - point, normal) >= 0 (cuts.h).
//
// Paths: relative mesh files, the anatomy and the files of mask regions
// ("mask:rel.nii") are relative to the JSON file's folder; loading makes
// them that folder joined with them (so they work from the current
// directory); saving writes a path that lies under the new file's folder
// relative to it, any other absolute.
//
// Loading is strict, safe on untrusted input, and names the place: an unknown
// or repeated key anywhere, a wrong type, a missing required key, a bad
// region, plane, slab or built-in mesh, a version other than 1 is an Error
// "FILE: rois[2]: unknown key \"colour\"" (one line). Files named inside
// (meshes, masks, anatomy) are not opened by loadRoiSet except where
// parseRegion opens a mask's.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "select/cuts.h"
#include "select/fiber_filter.h"
#include "select/region.h"

namespace fibscope {

inline constexpr int kRoiSetVersion = 1;

enum class RoiRole { Include, Exclude, IncludeOrdered };
// "include", "exclude", "include_ordered".
const char* roiRoleName(RoiRole role);

struct Roi {
  std::string name;
  Region region;
  RoiRole role = RoiRole::Include;
  bool enabled = true;
};

struct RoiClipPlane {
  ClipPlane plane;
  bool enabled = true;
};

struct RoiScalarRange {
  ScalarRange range;
  bool enabled = true;
};

struct RoiCutMesh {
  MeshCut cut;  // cut.spec: a built-in shape or an OBJ path (resolved, see above)
  bool enabled = true;
};

struct RoiSet {
  std::vector<Roi> rois;
  bool ends_only = false;
  double min_length_mm = NAN;  // NaN: no limit
  double max_length_mm = NAN;
  std::vector<RoiScalarRange> scalar_ranges;
  std::vector<RoiClipPlane> clip_planes;
  std::optional<Slab> slab;
  std::vector<RoiCutMesh> cut_meshes;
  std::string anatomy;  // "": none
};

RoiSet loadRoiSet(const std::string& path);
// The same from JSON text; `path` names it in messages and its folder is
// the one relative paths are resolved against.
RoiSet parseRoiSet(const std::string& json_text, const std::string& path);

// Writes the set to `path` atomically (a temporary file renamed over it:
// OutputFile), replacing a file there. Keys with nothing to say (a NaN
// length, no slab, no anatomy) are left out. Throws Error where it cannot
// write.
void saveRoiSet(const RoiSet& set, const std::string& path);
// The JSON text saveRoiSet writes for `path` (paths relative to its folder).
std::string roiSetJson(const RoiSet& set, const std::string& path);

// The criteria of the enabled ROIs (in their order within each role), the
// ends-only flag, the length limits and the enabled scalar ranges, for
// FiberFilter.
FilterCriteria filterCriteria(const RoiSet& set);
// The enabled cuts.
CutSet cutSet(const RoiSet& set);
// A set's criteria with the command line's: its regions appended after the
// set's, ends only where either asks, a length limit given on the command
// line (not NaN) replacing the set's, the command line's scalar ranges
// after the set's.
FilterCriteria mergeCriteria(FilterCriteria set, const FilterCriteria& command_line);

// The path rules above, exposed for the tests: `path` joined to `folder`
// when relative (resolve), or written relative to `folder` where it lies
// under it and absolute otherwise (!resolve). A region spec names a file
// only as "mask:PATH"; other kinds come back unchanged.
std::string pathAgainstFolder(const std::string& path, const std::string& folder, bool resolve);
std::string regionSpecAgainstFolder(const std::string& spec, const std::string& folder, bool resolve);

}  // namespace fibscope
