// NIfTI volumes: anatomical images for slices, masks for regions of interest
// (DESIGN.md section 2).
//
// Reads NIfTI-1 and NIfTI-2, single files (.nii) and header/image pairs
// (.hdr with its .img), each optionally gzipped (.nii.gz, .hdr + .img.gz:
// told by the gzip magic, not the name), in either byte order, of datatype
// uint8, int8, int16, uint16, int32, uint32, int64, uint64, float32 or
// float64. An image of 4 or more dimensions gives its first 3-D volume (the
// file must still hold them all: told by its size, or by reading a gzip
// file through, without keeping them); one of 1 or 2 dimensions is a volume
// of size 1 along the missing axes.
//
// The header and the voxels are read by fibscope (through zlib) with
// libnifti2's header layouts (nifti_header.h), not by libnifti's reader,
// which would load every volume of a 4-D file, prints to stderr and has
// exit paths.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace fibscope {

struct NiftiVolume {
  std::string path;
  glm::ivec3 dims{0};              // voxels along i, j, k
  glm::dvec3 voxel_size_mm{0.0};   // |pixdim[1..3]|, nibabel's get_zooms()
  glm::dmat4 voxel_to_world{1.0};  // (i, j, k, 1) -> RAS+ mm, as nibabel's img.affine (nifti_header.h)
  glm::dmat4 world_to_voxel{1.0};  // its inverse
  std::string affine_source;       // "sform", "qform" or "pixdim"
  int nifti_version = 1;           // 1 or 2
  std::string datatype;            // "uint8", ..., "float64"
  uint64_t volumes = 1;            // in the file; only the first is read
  // One value per voxel, i fastest, then j, then k: the stored value, times
  // scl_slope plus scl_inter (in double, rounded to float) unless the slope
  // is 0 or not finite, as nibabel's get_fdata(). See NiftiValues.
  std::vector<float> values;
  float min = NAN, max = NAN;  // of the finite values; NaN when there is none

  size_t index(int i, int j, int k) const { return (size_t(k) * size_t(dims.y) + size_t(j)) * size_t(dims.x) + size_t(i); }
  // The value at voxel (i, j, k), which must be inside dims.
  float value(int i, int j, int k) const { return values[index(i, j, k)]; }
};

enum class NiftiValues {
  Scaled,       // the scaled values (above)
  MrtrixMask,   // 1 where MRtrix3 reads the voxel as true when it opens the
                // image as a mask (Image<bool>: the scaled value, in double,
                // is finite and rounds half away from zero to non-zero, i.e.
                // |value| >= 0.5), else 0
};

// A bound on the voxels of the volume a caller accepts (0: only the
// header's own limits, nifti_header.h), and what it is for, for the message.
struct NiftiVoxelLimit {
  uint64_t max_voxels = 0;
  std::string_view what;  // "an anatomical image (512 MiB as float)"
};

// Reads `path`. Memory: the values (4 bytes a voxel of one volume) and a
// 1 MiB buffer, whatever the header claims. Safe on untrusted files: throws
// Error "PATH: ..." (one line) for a missing or unreadable file, a file that
// is not NIfTI, a header nifti_header.h refuses (datatype, dims, pixdim,
// scaling, singular or non-finite affine), a volume of more voxels than
// `limit` allows (told by the header, before any voxel is read), voxel data
// shorter than the header says (plain or gzipped) and corrupt gzip data.
NiftiVolume loadNiftiVolume(const std::string& path, NiftiValues values = NiftiValues::Scaled,
                            const NiftiVoxelLimit& limit = {});

}  // namespace fibscope
