// Anatomical slices on the CPU side (DESIGN.md section 2): the volume's
// grid, the world planes of its slices (the slab follows them), the default
// display range and slice positions, and the depth range a camera needs to
// see the whole volume. The GPU side is render/gpu/anatomy.h (the values
// on the device) and the anatomy stage (shaders/anatomy_slices.comp).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <string_view>

#include "io/nifti_volume.h"
#include "render/camera.h"
#include "render/clip_planes.h"
#include "render/render_settings.h"

namespace fibscope {

// The most voxels an anatomical volume may have: 512^3, 512 MiB of float
// values on the device (a 1 mm T1 has 16 M, a 0.7 mm one 40 M).
inline constexpr uint64_t kMaxAnatomyVoxels = uint64_t(1) << 27;

// Reads `path` as an anatomical image (loadNiftiVolume, scaled values).
// Throws Error "PATH: ..." (one line) as loadNiftiVolume does, also for a
// volume of more than kMaxAnatomyVoxels voxels (told by its header, before
// the voxels are read). Safe on untrusted files.
NiftiVolume loadAnatomyVolume(const std::string& path);

// What the slices need of a volume: its voxel grid and the affine nibabel
// chooses (voxel centres at integer coordinates).
struct AnatomyGrid {
  glm::ivec3 dims{0};
  glm::dmat4 voxel_to_world{1.0};
  glm::dmat4 world_to_voxel{1.0};
};
AnatomyGrid anatomyGrid(const NiftiVolume& volume);

// The world plane of the slice of `axis` (0 = i, 1 = j, 2 = k) at voxel
// coordinate `position`: (n, d) with n the unit normal towards increasing
// voxel coordinate, n.p + d = 0 on the plane.
PlaneEq slicePlane(const AnatomyGrid& grid, int axis, double position);

// The voxel axis (0 = i, 1 = j, 2 = k) whose slices are the `view`'s
// ("sagittal", "coronal", "axial", as mrview and ROI sets name them): the
// one whose slice normal lies nearest world x, y or z (i, j, k for an image
// stored in RAS order; an oblique or permuted one picks its own). -1 for
// another word.
int anatomicalSliceAxis(const AnatomyGrid& grid, std::string_view view);
// The view whose slices `axis` holds: its normal's largest world component.
std::string_view sliceAxisView(const AnatomyGrid& grid, int axis);

// `settings` with slab_plane at the active slice's plane when
// slab_follows_slice is set (else unchanged).
RenderSettings withSlabFollowingSlice(const RenderSettings& settings, const AnatomyGrid& grid);

// The display range render and the viewer start with: the 2nd and 98th
// percentiles of the finite values (nearest rank: the sorted values' entry
// round(p (n - 1))), of at most 2^22 values taken at an even stride (every
// value of a volume of up to 4 M voxels). Where those are equal (a mask
// that is mostly 0), the finite min and max; where those are equal too,
// [v - 1, v], so that the value shows white. No finite value: [0, 1].
struct ValueRange {
  float min = 0, max = 1;
};
ValueRange robustValueRange(std::span<const float> values);

// The volume's centre along `axis` as a voxel coordinate: (dim - 1) / 2.
float sliceCentre(const AnatomyGrid& grid, int axis);

// The settings render and the viewer start a volume with: slices at the
// centre and the display range `robust`, except for the settings `given`
// says the user gave ("slice-i", ..., "anatomy-range").
void fitAnatomySettings(RenderSettings& settings, const AnatomyGrid& grid, ValueRange robust,
                        const std::function<bool(std::string_view)>& given);

// The 8 corners of the volume's extent (voxel coordinates -0.5 and
// dim - 0.5) in world mm.
std::array<Vec3d, 8> volumeCorners(const AnatomyGrid& grid);

}  // namespace fibscope
