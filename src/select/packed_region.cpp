#include "select/packed_region.h"

#include <cmath>
#include <limits>

#include <algorithm>
#include <glm/glm.hpp>

#include "core/error.h"
#include "select/voxel_mask.h"

namespace fibscope {
namespace {

// The smallest float >= d / the largest float <= d: for every float p,
// p >= d  <=>  p >= floatAtLeast(d), and p <= d  <=>  p <= floatAtMost(d).
float floatAtLeast(double d) {
  float f = float(d);
  if (double(f) < d) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}
float floatAtMost(double d) {
  float f = float(d);
  if (double(f) > d) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}

shader::vec3 toFloats(const std::array<double, 3>& v) { return {float(v[0]), float(v[1]), float(v[2])}; }

void setBox(shader::FilterRegion& r, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  // Outward by more than the float rounding of anything tested against it.
  for (int k = 0; k < 3; ++k) {
    const double pad = 1e-5 * (std::fabs(lo[k]) + std::fabs(hi[k]) + 1.0);
    r.box[k] = floatAtMost(lo[k] - pad);
    r.box[3 + k] = floatAtLeast(hi[k] + pad);
  }
}

}  // namespace

OrientedBoxFloats orientedBoxFloats(const OrientedBoxRegion& box) {
  OrientedBoxFloats f;
  f.center = toFloats(box.center);
  f.half_size = toFloats(box.half);
  for (int k = 0; k < 3; ++k) f.axes[k] = toFloats(box.axes[k]);
  return f;
}

void setRegionBox(shader::FilterRegion& r, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  setBox(r, lo, hi);
}

shader::FilterRegion packRegion(const Region& region) {
  shader::FilterRegion r{};
  if (const auto* s = std::get_if<SphereRegion>(&region)) {
    r.kind = shader::kFilterSphere;
    for (int k = 0; k < 3; ++k) r.v[k] = s->center[k];
    r.v[3] = s->radius;
    const double rad = s->radius;
    setBox(r, {s->center[0] - rad, s->center[1] - rad, s->center[2] - rad},
           {s->center[0] + rad, s->center[1] + rad, s->center[2] + rad});
  } else if (const auto* b = std::get_if<BoxRegion>(&region)) {
    r.kind = shader::kFilterBox;
    for (int k = 0; k < 3; ++k) {
      r.v[k] = floatAtLeast(b->min[k]);
      r.v[3 + k] = floatAtMost(b->max[k]);
    }
    setBox(r, b->min, b->max);
  } else if (const auto* o = std::get_if<OrientedBoxRegion>(&region)) {
    r.kind = shader::kFilterOrientedBox;
    const OrientedBoxFloats f = orientedBoxFloats(*o);
    const shader::vec3 parts[5] = {f.center, f.half_size, f.axes[0], f.axes[1], f.axes[2]};
    for (int i = 0; i < 5; ++i)
      for (int k = 0; k < 3; ++k) r.v[3 * i + k] = parts[i][k];
    std::array<double, 3> lo{}, hi{};
    for (int k = 0; k < 3; ++k) {
      double reach = 0;
      for (int a = 0; a < 3; ++a) reach += std::fabs(o->axes[a][k]) * o->half[a];
      lo[k] = o->center[k] - reach;
      hi[k] = o->center[k] + reach;
    }
    setBox(r, lo, hi);
  } else {
    const VoxelMask& m = *std::get<MaskRegion>(region).mask;
    r.kind = shader::kFilterMask;
    r.nx = uint32_t(m.size[0]);
    r.ny = uint32_t(m.size[1]);
    r.nz = uint32_t(m.size[2]);
    for (int i = 0; i < 3; ++i) {
      const shader::vec4& row = m.world_to_voxel[i];
      r.v[4 * i] = row.x;
      r.v[4 * i + 1] = row.y;
      r.v[4 * i + 2] = row.z;
      r.v[4 * i + 3] = row.w;
    }
    // The grid's world box: its corners (voxel faces at -0.5 and size -
    // 0.5) through the inverse of the rows, padded by setBox.
    glm::dmat4 w2v(1.0);
    for (int i = 0; i < 3; ++i)
      for (int c = 0; c < 4; ++c) w2v[c][i] = r.v[4 * i + c];
    const glm::dmat4 v2w = glm::inverse(w2v);
    std::array<double, 3> lo, hi;
    lo.fill(INFINITY);
    hi.fill(-INFINITY);
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec4 v((corner & 1 ? m.size[0] : 0) - 0.5, (corner & 2 ? m.size[1] : 0) - 0.5,
                         (corner & 4 ? m.size[2] : 0) - 0.5, 1.0);
      const glm::dvec4 w = v2w * v;
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], w[k]);
        hi[k] = std::max(hi[k], w[k]);
      }
    }
    // Half a voxel more: rounding to the nearest voxel reaches that far.
    double voxel = 0;
    for (int k = 0; k < 3; ++k) voxel = std::max(voxel, glm::length(glm::dvec3(v2w[k])));
    for (int k = 0; k < 3; ++k) {
      lo[k] -= voxel;
      hi[k] += voxel;
    }
    setBox(r, lo, hi);
  }
  return r;
}

}  // namespace fibscope
