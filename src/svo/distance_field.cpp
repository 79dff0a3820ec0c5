#include "svo/distance_field.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/error.h"
#include "svo/svo_build.h"

namespace fibscope {

shader::DfGrid DistanceFieldGrid::shaderGrid() const {
  shader::DfGrid g{};
  g.origin_x = origin.x;
  g.origin_y = origin.y;
  g.origin_z = origin.z;
  g.voxel = voxel;
  g.size_x = size.x;
  g.size_y = size.y;
  g.size_z = size.z;
  g.band = band;
  return g;
}

DistanceFieldGrid chooseDistanceFieldGrid(const TubeModel& model, float voxel_mm, uint64_t max_bytes) {
  if (!std::isfinite(voxel_mm) || voxel_mm < 0.0f)
    throw Error("distance field: the voxel size must be >= 0 mm (0: automatic), got " + std::to_string(voxel_mm));
  if (model.segments.empty()) throw Error("distance field: no tube segment");
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  float r_max = 0.0f;
  for (const shader::TubeSegment& s : model.segments) {
    const SvoCapsule c = svoCapsule(model, s);
    lo = glm::min(lo, glm::min(c.a, c.b));
    hi = glm::max(hi, glm::max(c.a, c.b));
    r_max = std::max(r_max, c.radius);
  }
  const bool automatic = voxel_mm == 0.0f;
  float voxel = automatic ? std::max(r_max, 1e-3f) : voxel_mm;
  DistanceFieldGrid grid;
  for (;;) {
    const float band = shader::kDfBandVoxels * voxel;
    const glm::vec3 pad(r_max + band);
    const glm::vec3 extent = hi - lo + 2.0f * pad;
    const glm::dvec3 cells = glm::ceil(glm::dvec3(extent) / double(voxel));
    const double voxels = cells.x * cells.y * cells.z;
    if (automatic && voxels > double(shader::kDfMaxAutoVoxels)) {
      voxel *= 1.25f;
      continue;
    }
    if (voxels * sizeof(float) > double(max_bytes))
      throw Error("distance field: a voxel of " + std::to_string(voxel) + " mm needs " +
                  std::to_string(uint64_t(cells.x)) + " x " + std::to_string(uint64_t(cells.y)) + " x " +
                  std::to_string(uint64_t(cells.z)) + " voxels (" + std::to_string(voxels * 4.0 / 1e6) +
                  " MB), more than " + std::to_string(double(max_bytes) / 1e6) + " MB: choose a larger --df-voxel");
    grid.voxel = voxel;
    grid.band = band;
    grid.size = glm::uvec3(glm::max(cells, glm::dvec3(1.0)));
    // Centred on the tubes' box.
    grid.origin = 0.5f * (lo + hi) - 0.5f * glm::vec3(grid.size) * voxel;
    return grid;
  }
}

float bruteForceDistance(const TubeModel& model, const glm::vec3& p, float band) {
  float best = band;
  for (const shader::TubeSegment& s : model.segments) best = std::min(best, capsuleDistance(svoCapsule(model, s), p));
  return best;
}

namespace {

float value(const DistanceFieldGrid& grid, const std::vector<float>& values, glm::ivec3 v) {
  v = glm::clamp(v, glm::ivec3(0), glm::ivec3(grid.size) - 1);
  return values[(size_t(v.z) * grid.size.y + size_t(v.y)) * grid.size.x + size_t(v.x)];
}

bool inside(const DistanceFieldGrid& grid, const glm::vec3& p) {
  const glm::vec3 hi = grid.origin + glm::vec3(grid.size) * grid.voxel;
  return glm::all(glm::greaterThanEqual(p, grid.origin)) && glm::all(glm::lessThan(p, hi));
}

}  // namespace

float sampleDistanceField(const DistanceFieldGrid& grid, const std::vector<float>& values, const glm::vec3& p) {
  if (!inside(grid, p)) return grid.band;
  const glm::vec3 g = (p - grid.origin) / grid.voxel - 0.5f;
  const glm::vec3 i0 = glm::floor(g);
  const glm::vec3 f = g - i0;
  const glm::ivec3 v(i0);
  return shader::dfTrilinear(value(grid, values, v), value(grid, values, v + glm::ivec3(1, 0, 0)),
                             value(grid, values, v + glm::ivec3(0, 1, 0)), value(grid, values, v + glm::ivec3(1, 1, 0)),
                             value(grid, values, v + glm::ivec3(0, 0, 1)), value(grid, values, v + glm::ivec3(1, 0, 1)),
                             value(grid, values, v + glm::ivec3(0, 1, 1)), value(grid, values, v + glm::ivec3(1, 1, 1)),
                             f.x, f.y, f.z);
}

float distanceFieldAo(const DistanceFieldGrid& grid, const std::vector<float>& values, const glm::vec3& p,
                      const glm::vec3& n, uint32_t steps, float delta, float strength) {
  const float eps = shader::kDfSelfOffsetVoxels * grid.voxel;
  float sum = 0.0f, weight = 0.5f;
  for (uint32_t i = 1; i <= steps; ++i, weight *= 0.5f) {
    const float h = eps + float(i) * delta;
    const float d = sampleDistanceField(grid, values, p + h * n);
    sum += weight * std::max(std::min(h, grid.band) - d, 0.0f);
  }
  return std::clamp(1.0f - strength / delta * sum, 0.0f, 1.0f);
}

float distanceFieldShadow(const DistanceFieldGrid& grid, const std::vector<float>& values, const glm::vec3& p,
                          const glm::vec3& n, const glm::vec3& l, float softness) {
  if (!(glm::dot(n, l) > 0.0f)) return 1.0f;
  const float s = shader::kDfShadowStartVoxels * grid.voxel;
  const float min_step = shader::kDfShadowMinStepVoxels * grid.voxel;
  const float open = shader::kDfShadowOpenFraction * grid.band;
  const glm::vec3 o = p + s * n;
  float t = s, shadow = 1.0f;
  for (uint32_t j = 0; j < shader::kDfShadowSteps; ++j) {
    const glm::vec3 q = o + t * l;
    if (!inside(grid, q)) break;
    const float d = sampleDistanceField(grid, values, q);
    if (d < open) shadow = std::min(shadow, softness * d / t);
    if (shadow <= 0.0f) break;
    t += std::max(d, min_step);
  }
  return std::clamp(shadow, 0.0f, 1.0f);
}

}  // namespace fibscope
