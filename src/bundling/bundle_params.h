// The parameters of fiber bundling (FiberVisualizer section 7), the
// paper's values as defaults. Lengths are in voxels of the bundling grid
// unless named _mm; `voxel_mm` and `step_mm` of 0 take the paper's
// fractions of the model's bounding box.
#pragma once

#include <cstdint>
#include <string>

namespace fibscope {

enum class BundleMode : uint8_t {
  Isotropic,    // the paper's density: every sample splats the same kernel
  Anisotropic,  // after Bouma, Hurter, Telea: a kernel elongated along each sample's fiber
};

struct BundleParams {
  BundleMode mode = BundleMode::Isotropic;
  uint32_t iterations = 15;
  double radius = 10;          // kernel radius R (voxels) of the first iteration
  double radius_decay = 0.95;  // R is multiplied by this after each iteration
  double advection = 1.0;      // advection step as a multiple of R (the paper: R)
  double voxel_mm = 0;         // 0: voxel_fraction of the box's largest side
  double voxel_fraction = 0.003;
  double step_mm = 0;  // resampling interval; 0: step_fraction of the box's z extent
  double step_fraction = 0.01;
  double smoothing = 0.9;         // phi: weight of the neighbours' mean
  double smoothing_length = 1.0;  // L as a multiple of R (the paper: L = R)
  double relaxation = 0.85;       // alpha: 1 keeps the bundled positions, 0 the original ones
  bool anchor_ends = false;       // true: fiber end points do not move
  double anisotropy = 0.5;        // anisotropic mode: the kernel's radius across the fiber / along it
  // Structure-aware advection (either mode; docs/BUNDLING.md): the step is
  // the gradient filtered by the density's structure tensor, so a sheet of
  // fibers contracts across its plane and does not break into strands.
  bool structure_aware = false;
  uint32_t structure_power = 2;   // the filter (J / lambda1)^power: higher selects the dominant direction harder
  double structure_scale = 1.0;   // the tensor's cells: structure_scale x the first R voxels a side (at least 2)
};

// "" when the parameters are usable, else one line naming the parameter,
// its value and the allowed range.
std::string bundleParamsProblem(const BundleParams& params);
// Throws Error with bundleParamsProblem's message.
void validateBundleParams(const BundleParams& params);

// "isotropic" / "anisotropic"; parseBundleMode throws Error for others.
const char* bundleModeName(BundleMode mode);
BundleMode parseBundleMode(const std::string& name);

}  // namespace fibscope
