// The tubes' dense low-resolution distance field for ambient occlusion and
// soft shadows (issue 16 item 4; shaders/shared/distance_field.h has the
// layout and the formulas): the grid chosen for a tube model, and the CPU
// references the tests compare the GPU against: the field by brute force
// over the capsules, its trilinear sample, and the AO and shadow factors of
// a point evaluated on a given field exactly as df_ao.comp and
// df_shadow.comp do (float, the same order of operations).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "shared/distance_field.h"
#include "tubes/tube_model.h"

namespace fibscope {

struct DistanceFieldGrid {
  glm::vec3 origin{0.0f};  // corner of voxel (0, 0, 0), mm
  float voxel = 1.0f;      // mm
  glm::uvec3 size{0u};
  float band = 0.0f;  // mm: kDfBandVoxels * voxel
  uint64_t voxels() const { return uint64_t(size.x) * size.y * size.z; }
  uint64_t bytes() const { return voxels() * sizeof(float); }
  glm::vec3 center(uint32_t x, uint32_t y, uint32_t z) const {
    return origin + (glm::vec3(float(x), float(y), float(z)) + 0.5f) * voxel;
  }
  shader::DfGrid shaderGrid() const;
};

// The grid for `model`: the box of its capsules widened by the largest
// radius plus the band, at `voxel_mm` when > 0, else (0) at the largest
// tube radius, coarsened by 1.25x until the field holds at most
// kDfMaxAutoVoxels voxels (64 MB of floats). Throws Error when voxel_mm is
// < 0 or not finite, the model has no segment, or a given voxel needs more
// than `max_bytes` (naming the size it would need).
DistanceFieldGrid chooseDistanceFieldGrid(const TubeModel& model, float voxel_mm,
                                          uint64_t max_bytes = uint64_t(1) << 31);

// min over the model's capsules of the signed distance at p, clamped to
// `band` (the field's value at a voxel centre, by brute force).
float bruteForceDistance(const TubeModel& model, const glm::vec3& p, float band);

// The field's trilinear sample at p (the band outside the box), as
// glsl/distance_field.glsl's dfSample. values: grid.voxels() floats.
float sampleDistanceField(const DistanceFieldGrid& grid, const std::vector<float>& values, const glm::vec3& p);

// df_ao.comp's factor at surface point p with unit normal n.
float distanceFieldAo(const DistanceFieldGrid& grid, const std::vector<float>& values, const glm::vec3& p,
                      const glm::vec3& n, uint32_t steps, float delta, float strength);
// df_shadow.comp's factor at p with normal n towards the unit light
// direction l.
float distanceFieldShadow(const DistanceFieldGrid& grid, const std::vector<float>& values, const glm::vec3& p,
                          const glm::vec3& n, const glm::vec3& l, float softness);

}  // namespace fibscope
