#include "bundling/bundle_params.h"

#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace fibscope {

namespace {

std::string outOfRange(const char* name, double value, const char* range) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "bundling: %s is %g, must be %s", name, value, range);
  return buf;
}

}  // namespace

std::string bundleParamsProblem(const BundleParams& p) {
  if (p.iterations < 1 || p.iterations > 1000) return outOfRange("iterations", p.iterations, "1 to 1000");
  if (!(p.radius >= 1 && p.radius <= 256)) return outOfRange("radius", p.radius, "1 to 256 voxels");
  if (!(p.radius_decay > 0 && p.radius_decay <= 1)) return outOfRange("radius decay", p.radius_decay, "in (0, 1]");
  if (!(p.advection > 0 && p.advection <= 4)) return outOfRange("advection", p.advection, "in (0, 4] radii");
  if (!(p.voxel_mm >= 0 && std::isfinite(p.voxel_mm)))
    return outOfRange("voxel", p.voxel_mm, "0 (automatic) or more mm");
  if (!(p.voxel_fraction > 0 && p.voxel_fraction <= 1))
    return outOfRange("voxel fraction", p.voxel_fraction, "in (0, 1]");
  if (!(p.step_mm >= 0 && std::isfinite(p.step_mm))) return outOfRange("step", p.step_mm, "0 (automatic) or more mm");
  if (!(p.step_fraction > 0 && p.step_fraction <= 1)) return outOfRange("step fraction", p.step_fraction, "in (0, 1]");
  if (!(p.smoothing >= 0 && p.smoothing <= 1)) return outOfRange("smoothing", p.smoothing, "in [0, 1]");
  if (!(p.smoothing_length >= 0 && p.smoothing_length <= 100))
    return outOfRange("smoothing length", p.smoothing_length, "0 to 100 radii");
  if (!(p.relaxation >= 0 && p.relaxation <= 1)) return outOfRange("relaxation", p.relaxation, "in [0, 1]");
  if (!(p.anisotropy >= 0.05 && p.anisotropy <= 1)) return outOfRange("anisotropy", p.anisotropy, "in [0.05, 1]");
  if (p.structure_power < 1 || p.structure_power > 8)
    return outOfRange("structure power", p.structure_power, "1 to 8");
  if (!(p.structure_scale >= 0.1 && p.structure_scale <= 2))
    return outOfRange("structure scale", p.structure_scale, "in [0.1, 2] radii");
  return "";
}

void validateBundleParams(const BundleParams& params) {
  const std::string problem = bundleParamsProblem(params);
  if (!problem.empty()) throw Error(problem);
}

const char* bundleModeName(BundleMode mode) { return mode == BundleMode::Isotropic ? "isotropic" : "anisotropic"; }

BundleMode parseBundleMode(const std::string& name) {
  if (name == "isotropic") return BundleMode::Isotropic;
  if (name == "anisotropic") return BundleMode::Anisotropic;
  throw Error("bundling: unknown mode '" + name + "' (isotropic or anisotropic)");
}

}  // namespace fibscope
