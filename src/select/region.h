// Regions of interest in world space (RAS+ mm) that the fiber filter tests
// streamline vertices against (DESIGN.md section 2, "selection state").
//
// Spec text (the command line's --include / --exclude, the ROI sets):
//   sphere:X,Y,Z,R      centre and radius (mm); also plain X,Y,Z,R, as
//                       MRtrix3's tckedit writes a sphere
//   box:X0,Y0,Z0,X1,Y1,Z1
//                       axis-aligned, two opposite corners in any order
//   obox:CX,CY,CZ,SX,SY,SZ,AX,AY,AZ
//                       oriented box: centre, full sizes along its own axes,
//                       and the rotation of those axes from x, y, z: AX
//                       degrees about x, then AY about y, then AZ about z
//   mask:PATH           a NIfTI image (.nii, .nii.gz, .hdr): its set voxels,
//                       with tckedit's semantics (select/voxel_mask.h);
//                       PATH is everything after "mask:", ':' and ',' too
// Boundaries count as inside.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <variant>

#include "select/voxel_mask.h"

namespace fibscope {

// The largest coordinate, radius or size a region's spec may give (mm): 1 km
// from the origin, as an OBJ mesh's (io/obj_mesh.h). The tests run in float
// and cut meshes are built from regions: beyond it corners and squared
// distances overflow to infinity.
inline constexpr double kMaxRegionMm = 1e6;

// Inside when the squared distance to the centre is <= radius^2, computed
// in float as MRtrix3 does (so a vertex on the boundary is decided the same).
struct SphereRegion {
  std::array<float, 3> center = {0, 0, 0};
  float radius = 1;
};

struct BoxRegion {
  std::array<double, 3> min = {0, 0, 0}, max = {0, 0, 0};
};

struct OrientedBoxRegion {
  std::array<double, 3> center = {0, 0, 0};
  std::array<double, 3> half = {0.5, 0.5, 0.5};        // half sizes along its axes (mm)
  std::array<double, 3> angles_deg = {0, 0, 0};        // the spec's rotation
  std::array<std::array<double, 3>, 3> axes = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};  // from the angles: unit, orthogonal
};

// Loaded once, when the spec is parsed; copies of the region share it.
struct MaskRegion {
  std::string path;
  std::shared_ptr<const VoxelMask> mask;
};

using Region = std::variant<SphereRegion, BoxRegion, OrientedBoxRegion, MaskRegion>;

// Whether world point p (mm) lies in the region.
bool regionContains(const Region& region, const float* p);

// The region a spec names. Throws Error "SPEC: ..." (one line: what was
// expected) for anything else: an unknown kind, a wrong number of values,
// non-finite values, a coordinate, radius or size beyond kMaxRegionMm, a
// radius or size <= 0 (in float); for a mask whose image cannot be
// used, loadVoxelMask's Error "PATH: ...". Safe on untrusted text and files.
Region parseRegion(std::string_view spec);
// The spec of a region: parseRegion(regionSpec(r)) gives r again (to the
// 9 significant digits printed; a mask's file is read again).
std::string regionSpec(const Region& region);

}  // namespace fibscope
