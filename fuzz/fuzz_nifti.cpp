// libFuzzer target for the NIfTI volume reader (io/nifti_volume.h).
//
// Each input is read as a .nii twice, with scaled values and as MRtrix3's
// mask (a gzip input is told by its magic, so .nii.gz inputs reach zlib).
// Only fibscope::Error is an accepted outcome, with a one-line message.
// Whatever loads must keep its promises: one value per voxel of the dims,
// a finite affine whose inverse is finite, min <= max, mask values 0 or 1.
//
// Seeds: fuzz/seeds/nifti.py (small NIfTI-1 and -2 files, plain and gzip).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "fuzz_support.h"
#include "io/nifti_volume.h"

namespace {

void check(const fibscope::NiftiVolume& v, fibscope::NiftiValues mode) {
  if (v.dims.x < 1 || v.dims.y < 1 || v.dims.z < 1) std::abort();
  if (v.values.size() != size_t(v.dims.x) * size_t(v.dims.y) * size_t(v.dims.z)) std::abort();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(v.voxel_to_world[c][r]) || !std::isfinite(v.world_to_voxel[c][r])) std::abort();
  if (std::isnan(v.min) != std::isnan(v.max) || v.min > v.max) std::abort();
  if (mode == fibscope::NiftiValues::MrtrixMask)
    for (const float x : v.values)
      if (x != 0.0f && x != 1.0f) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = fibscope::fuzz::scratchPath("nifti", "input.nii");
  fibscope::fuzz::writeInput(path, data, size);
  for (const auto mode : {fibscope::NiftiValues::Scaled, fibscope::NiftiValues::MrtrixMask}) {
    try {
      check(fibscope::loadNiftiVolume(path, mode), mode);
    } catch (const fibscope::Error& e) {
      fibscope::fuzz::checkMessage(e);
    }
  }
  std::remove(path.c_str());
  return 0;
}
