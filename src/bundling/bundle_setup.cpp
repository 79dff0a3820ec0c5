#include "bundling/bundle_setup.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

namespace fibscope {

namespace {

double fiberLength(const Tractogram& t, size_t f) {
  double len = 0;
  for (uint64_t i = t.offsets[f] + 1; i < t.offsets[f + 1]; ++i) {
    const float* a = t.point(i - 1);
    const float* b = t.point(i);
    len += glm::length(glm::dvec3(b[0], b[1], b[2]) - glm::dvec3(a[0], a[1], a[2]));
  }
  return len;
}

}  // namespace

uint32_t bundleSampleCount(double length_mm, double step_mm) {
  if (!(length_mm > 0)) return 1;
  return uint32_t(std::max(2.0, std::ceil(length_mm / step_mm) + 1));
}

BundleSetup planBundling(const Tractogram& t, const BundleParams& params) {
  validateBundleParams(params);
  if (t.pointCount() == 0) throw Error("bundling: the model has no point");
  if (t.pointCount() > std::numeric_limits<uint32_t>::max())
    throw Error("bundling: the model has more than 2^32 points");
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < t.pointCount(); ++i) {
    const glm::dvec3 p(t.point(i)[0], t.point(i)[1], t.point(i)[2]);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error("bundling: point " + std::to_string(i) + " is not finite");
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::dvec3 extent = hi - lo;
  const double largest = std::max({extent.x, extent.y, extent.z});
  if (!(largest > 0)) throw Error("bundling: the model has no extent (all its points coincide)");
  BundleSetup setup;
  BundleGrid& g = setup.grid;
  g.voxel = params.voxel_mm > 0 ? params.voxel_mm : params.voxel_fraction * largest;
  setup.step_mm = params.step_mm > 0 ? params.step_mm : params.step_fraction * (extent.z > 0 ? extent.z : largest);
  const double pad = params.radius * g.voxel;
  g.origin = lo - pad;
  double voxels = 1;
  for (int a = 0; a < 3; ++a) {
    const double n = std::ceil((extent[a] + 2 * pad) / g.voxel);
    if (!(n <= 1 << 20)) throw Error("bundling: the grid would have more than 2^20 voxels a side; give a larger voxel");
    g.size[a] = uint32_t(std::max(1.0, n));
    voxels *= g.size[a];
  }
  if (voxels > double(1u << 31))
    throw Error("bundling: the grid of " + std::to_string(g.size.x) + " x " + std::to_string(g.size.y) + " x " +
                std::to_string(g.size.z) + " voxels is too large; give a larger voxel");
  setup.sample_offsets.resize(t.streamlineCount() + 1);
  setup.sample_offsets[0] = 0;
  uint64_t total = 0;
  for (size_t f = 0; f < t.streamlineCount(); ++f) {
    total += t.pointsIn(f) == 0 ? 0 : bundleSampleCount(fiberLength(t, f), setup.step_mm);
    if (total > std::numeric_limits<uint32_t>::max())
      throw Error("bundling: more than 2^32 samples; give a larger step");
    setup.sample_offsets[f + 1] = uint32_t(total);
  }
  return setup;
}

double bundleRadius(const BundleParams& params, uint32_t iteration) {
  return params.radius * std::pow(params.radius_decay, double(iteration));
}

double bundleAdvectionStep(const BundleParams& params, const BundleSetup& setup, double radius) {
  return params.advection * radius * setup.grid.voxel;
}

uint32_t bundleSmoothingWindow(const BundleParams& params, const BundleSetup& setup, double radius) {
  if (!(params.smoothing_length > 0)) return 0;
  const double k = std::round(params.smoothing_length * radius * setup.grid.voxel / setup.step_mm);
  return uint32_t(std::clamp(k, 1.0, 1e6));
}

uint32_t bundleStructureCell(const BundleParams& params) {
  return uint32_t(std::max(2.0, std::round(params.structure_scale * params.radius)));
}

BundleGrid bundleStructureGrid(const BundleGrid& grid, uint32_t cell) {
  BundleGrid cells;
  cells.origin = grid.origin;
  cells.voxel = grid.voxel * cell;
  cells.size = (grid.size + (cell - 1)) / cell;
  return cells;
}

shader::BundleGridBlock bundleGridBlock(const BundleGrid& grid) {
  shader::BundleGridBlock b{};
  b.origin_x = float(grid.origin.x);
  b.origin_y = float(grid.origin.y);
  b.origin_z = float(grid.origin.z);
  b.voxel = float(grid.voxel);
  b.nx = grid.size.x;
  b.ny = grid.size.y;
  b.nz = grid.size.z;
  return b;
}

}  // namespace fibscope
