// What a bundling run fixes before its first iteration, computed once on
// the host and used alike by the GPU passes and the CPU reference: the
// voxel grid, the resampling interval and how many samples each fiber gets.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

#include "bundling/bundle_params.h"
#include "core/tractogram.h"
#include "shared/bundling.h"

namespace fibscope {

// Voxel (i, j, k) covers origin + voxel * [i, i + 1) x [j, j + 1) x [k, k + 1).
struct BundleGrid {
  glm::dvec3 origin{0.0};
  double voxel = 1;  // mm
  glm::uvec3 size{1u};
  uint64_t voxelCount() const { return uint64_t(size.x) * size.y * size.z; }
  uint64_t index(uint32_t x, uint32_t y, uint32_t z) const { return x + uint64_t(size.x) * (y + uint64_t(size.y) * z); }
};

struct BundleSetup {
  BundleGrid grid;
  double step_mm = 0;                    // the resampling interval asked for (a fiber's is len / (n - 1) <= it)
  std::vector<uint32_t> sample_offsets;  // fiber f's samples: [sample_offsets[f], sample_offsets[f + 1])
  uint32_t sampleCount() const { return sample_offsets.back(); }
};

// The samples of a fiber of arc length `length_mm` (computed in double):
// 1 for a fiber of no length, else max(2, ceil(length / step) + 1).
uint32_t bundleSampleCount(double length_mm, double step_mm);

// The grid over the model's bounding box widened by the first kernel radius
// on every side (so the kernel around a point near the box's faces is
// whole), its voxel params.voxel_mm or voxel_fraction of the box's largest
// side; the step params.step_mm or step_fraction of the box's z extent (its
// largest side for a flat model). Throws Error when the parameters are
// invalid, the model has no point or no extent, the grid would exceed
// 2^31 voxels or the samples 2^32.
BundleSetup planBundling(const Tractogram& tractogram, const BundleParams& params);

// R of iteration `iteration` (0-based): radius * radius_decay^iteration, voxels.
double bundleRadius(const BundleParams& params, uint32_t iteration);
// The advection step for kernel radius `radius` (voxels): advection * radius * voxel, mm.
double bundleAdvectionStep(const BundleParams& params, const BundleSetup& setup, double radius);
// The smoothing window k (samples each side) for kernel radius `radius`
// (voxels): round(smoothing_length * radius * voxel / step), at least 1
// when smoothing_length > 0.
uint32_t bundleSmoothingWindow(const BundleParams& params, const BundleSetup& setup, double radius);

// Structure-aware advection: the structure tensor is kept per cell of
// bundleStructureCell voxels a side, max(2, round(structure_scale x the
// first R)), fixed for the run (24 B of tensor and 4 B of mean density a
// cell: at most 3.5 B a voxel).
// Its grid: the voxel grid's origin, cells of cell x voxel mm, ceil(size /
// cell) a side (the last cell of an axis may hold fewer voxels).
uint32_t bundleStructureCell(const BundleParams& params);
BundleGrid bundleStructureGrid(const BundleGrid& grid, uint32_t cell);

// The grid as the shaders see it.
shader::BundleGridBlock bundleGridBlock(const BundleGrid& grid);

}  // namespace fibscope
