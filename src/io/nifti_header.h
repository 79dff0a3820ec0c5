// The NIfTI-1 / NIfTI-2 header (348 / 540 bytes, either byte order): its
// fields, their checks, and the voxel-to-world affine nibabel chooses.
//
// Checked here, before any voxel is read, so that a bad file is one Error
// naming it (never an allocation the file cannot back, never libnifti's
// stderr or exit paths): sizeof_hdr and magic, dim[0] in 1..7 and every used
// dim >= 1, a datatype fibscope reads, vox_offset, finite pixdim[1..3] and
// scl_inter (where scl_slope is used), a finite, invertible affine.
//
// The affine (NIfTI-1 spec, nibabel's Nifti1Header.get_best_affine):
//   sform_code != 0     the srow_x/y/z rows                       ("sform")
//   else qform_code != 0  R(quaternion) * diag(pixdim1, pixdim2, qfac * pixdim3)
//                       + qoffset, w = sqrt(1 - b²-c²-d²) (0 when that is
//                       negative by rounding), qfac = pixdim[0] when it is -1,
//                       else 1                                    ("qform")
//   else                nibabel's fallback: diag(-pixdim1, pixdim2, pixdim3)
//                       about the centre of the grid (radiological x, as
//                       Analyze)                                  ("pixdim")
// Both nibabel and MRtrix3 test the codes for != 0 (a negative code, which
// the spec does not allow, counts as set). When sform and qform are both set
// and disagree, nibabel and MRtrix3 (NIfTIUseSform, default true, with a
// warning) take the sform: so does fibscope. Where they differ:
//   - no code set: MRtrix3 takes an identity rotation about the grid's
//     centre (x not flipped), so such an image is mirrored left-right between
//     nibabel and mrview/tckedit; fibscope follows nibabel;
//   - nibabel silently replaces a zero pixdim by 1 and a qfac other than ±1
//     by 1; fibscope takes the qfac rule but refuses a zero pixdim where the
//     affine is built from it (a singular affine). MRtrix3 takes any
//     negative pixdim[0] as qfac -1.
#pragma once

#include <cstddef>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <string>

namespace fibscope {

struct NiftiHeader {
  int version = 1;            // 1 or 2
  bool swap = false;          // stored in the other byte order than this machine's
  bool separate_image = false;  // magic "ni1"/"ni2": the voxels are in a .img beside the .hdr
  size_t header_bytes = 348;  // 348 or 540
  int datatype = 0;           // NIfTI DT_ code
  size_t bytes_per_voxel = 0;
  int ndim = 0;               // dim[0]
  int64_t dim[8] = {};        // dim[1..ndim] >= 1; the unused ones are 1
  double pixdim[8] = {};      // as stored (pixdim[0] is qfac)
  int64_t vox_offset = 0;     // where the voxels start in the data file
  double scl_slope = 0, scl_inter = 0;
  int64_t qform_code = 0, sform_code = 0;
  double quatern[3] = {};     // b, c, d
  double qoffset[3] = {};
  double srow[3][4] = {};

  // The scaling nibabel applies: value = stored * slope + inter, unless the
  // slope is 0 or not finite.
  bool scaled() const { return scl_slope != 0 && std::isfinite(scl_slope); }
  // Voxels in one 3-D volume (dim 1..3) and volumes (dim 4..7) the file holds.
  uint64_t voxelsPerVolume() const { return uint64_t(dim[1]) * uint64_t(dim[2]) * uint64_t(dim[3]); }
  uint64_t volumes() const;
};

// Limits on what a header may claim: beyond them it is refused as absurd
// (before anything is allocated).
constexpr int64_t kNiftiMaxDim = int64_t(1) << 24;           // per axis
constexpr uint64_t kNiftiMaxVolumeVoxels = uint64_t(1) << 31;  // one 3-D volume
constexpr uint64_t kNiftiMaxVolumes = uint64_t(1) << 28;        // dims 4..7: the data stay below 2^62 bytes

// Parses and checks the first `size` bytes of `path` (at least 4; the 348 or
// 540 the header needs, else a "truncated header" Error). Throws Error
// "PATH: ..." for anything listed above. Safe on untrusted bytes.
NiftiHeader parseNiftiHeader(const std::string& path, const unsigned char* bytes, size_t size);

// The header's affine as nibabel chooses it (see above); `source` gets
// "sform", "qform" or "pixdim". Throws Error "PATH: ..." when it is not
// finite or not invertible (a zero column, a zero pixdim it is built from).
glm::dmat4 niftiAffine(const std::string& path, const NiftiHeader& h, std::string* source);

// The name of a NIfTI datatype code ("uint8", "RGB24", ...).
std::string niftiDatatypeName(int datatype);

}  // namespace fibscope
