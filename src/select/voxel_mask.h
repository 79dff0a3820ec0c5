// A NIfTI mask as a region of interest, with MRtrix3 tckedit's semantics
// (its Tractography::Mask and ROI::contains, 3.0.3), so that `fibscope
// filter --include mask:F` keeps what `tckedit -include F` keeps.
//
// A voxel is set when MRtrix3 reads it as true (a finite value that rounds
// half away from zero to non-zero: |value| >= 0.5 after scl_slope/inter,
// io/nifti_volume.h NiftiValues::MrtrixMask). A point is inside when its
// nearest voxel is set; outside the image is outside. The nearest voxel is
// found as tckedit finds it, in the grid tckedit builds:
//   1. the voxel axes as MRtrix3 reads them: the affine's column directions,
//      voxel sizes from pixdim (an sform whose column lengths differ from
//      pixdim by more than 1e-5 relative gives the lengths instead);
//   2. realigned as MRtrix3 realigns every image it opens: voxel axes
//      permuted and flipped so that axis i is the one nearest world axis i,
//      pointing the same way (so a half-way point goes to the voxel on the
//      R, A or S side whatever the file's storage order);
//   3. cropped to the set voxels' bounding box plus one voxel (its Mask
//      constructor does; the translation moves with it);
//   4. world -> voxel: the double inverse of that grid's voxel -> world,
//      rounded to float;
//   5. the float arithmetic and rounding of shaders/shared/voxel_mask.h.
// Steps 3 and 4 change no decision in exact arithmetic; they are kept so
// that the float rounding is tckedit's too (a point a few ulps from a voxel
// face goes the same way).
//
// Differences from tckedit, both in how the image is read, not in the rule:
// an image with no sform or qform code is placed as nibabel places it (x
// flipped about the grid's centre) where MRtrix3 takes x unflipped; MRtrix3
// fills a qform's w differently when b² + c² + d² is within 1e-7 of 1.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/nifti_volume.h"
#include "shared/glsl_cpp.h"

namespace fibscope {

struct VoxelMask {
  std::string path;
  int size[3] = {0, 0, 0};             // voxels of the cropped, realigned grid
  shader::vec4 world_to_voxel[3];      // its rows, float (shared/voxel_mask.h)
  std::vector<uint32_t> bits;          // voxel (i, j, k) is bit i + size0 (j + size1 k)
  uint64_t set_voxels = 0;

  // Whether world point p (RAS+ mm) is in a set voxel.
  bool contains(const float* p) const;
  // The voxel (of this grid) p falls in; false when outside the grid.
  bool voxelOf(const float* p, int voxel[3]) const;
};

// The mask of `volume`, whose values were read with NiftiValues::MrtrixMask.
// Throws Error "PATH: ..." when no voxel is set (tckedit refuses an empty
// mask too).
VoxelMask makeVoxelMask(const NiftiVolume& volume);

// Reads the NIfTI image `path` as a mask (loadNiftiVolume's errors, and
// makeVoxelMask's).
std::shared_ptr<const VoxelMask> loadVoxelMask(const std::string& path);

}  // namespace fibscope
