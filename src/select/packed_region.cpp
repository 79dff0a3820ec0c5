#include "select/packed_region.h"

#include <cmath>
#include <limits>

#include "core/error.h"

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
    throw Error("filter: " + regionSpec(region) + ": this kind of region is packed with its voxels");
  }
  return r;
}

}  // namespace fibscope
