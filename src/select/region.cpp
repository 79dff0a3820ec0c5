#include "select/region.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <vector>

#include "core/error.h"
#include "select/number_list.h"
#include "select/packed_region.h"

namespace fibscope {
namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

bool regionContains(const Region& region, const float* p) {
  if (const auto* s = std::get_if<SphereRegion>(&region)) {
    // As MRtrix3's ROI::contains: (pos - p).squaredNorm() <= radius^2, in float.
    // (The GPU filter's test: shared/fiber_filter.h.)
    return shader::filterSphereContains(s->center[0], s->center[1], s->center[2], s->radius,
                                        shader::vec3(p[0], p[1], p[2]));
  }
  if (const auto* b = std::get_if<BoxRegion>(&region)) {
    for (int k = 0; k < 3; ++k)
      if (!(p[k] >= b->min[k] && p[k] <= b->max[k])) return false;
    return true;
  }
  if (const auto* m = std::get_if<MaskRegion>(&region)) return m->mask->contains(p);
  // In float, as the GPU filter tests it (shared/fiber_filter.h): both
  // sides decide a vertex on a face alike.
  const OrientedBoxFloats f = orientedBoxFloats(std::get<OrientedBoxRegion>(region));
  return shader::filterOrientedBoxContains(f.center, f.half_size, f.axes[0], f.axes[1], f.axes[2],
                                           shader::vec3(p[0], p[1], p[2]));
}

Region parseRegion(std::string_view spec) {
  const std::string text(spec);
  const size_t colon = spec.find(':');
  const std::string_view kind = colon == std::string_view::npos ? std::string_view("sphere") : spec.substr(0, colon);
  if (kind == "mask") {
    const std::string path(spec.substr(colon + 1));
    if (path.empty()) fail(text, "expected a mask as mask:PATH (a NIfTI image)");
    return MaskRegion{path, loadVoxelMask(path)};
  }
  const std::string_view values = colon == std::string_view::npos ? spec : spec.substr(colon + 1);
  std::vector<double> v;
  const bool numbers = parseNumberList(values, v);
  // The first n values: coordinates and sizes (an oriented box's angles
  // are free). Called once the count is checked.
  const auto checkRange = [&](size_t n) {
    for (size_t i = 0; i < n; ++i)
      if (!(std::fabs(v[i]) <= kMaxRegionMm))
        fail(text, "a coordinate or size beyond " + number(kMaxRegionMm) + " mm (" + number(v[i]) + ")");
  };
  if (kind == "sphere") {
    if (!numbers || v.size() != 4)
      fail(text, "expected a sphere as sphere:X,Y,Z,R (mm; or X,Y,Z,R)");
    checkRange(4);
    if (!(float(v[3]) > 0)) fail(text, "a sphere's radius must be > 0 mm");
    return SphereRegion{{float(v[0]), float(v[1]), float(v[2])}, float(v[3])};
  }
  if (kind == "box") {
    if (!numbers || v.size() != 6) fail(text, "expected a box as box:X0,Y0,Z0,X1,Y1,Z1 (two opposite corners, mm)");
    checkRange(6);
    BoxRegion b;
    for (int k = 0; k < 3; ++k) {
      b.min[k] = std::min(v[k], v[k + 3]);
      b.max[k] = std::max(v[k], v[k + 3]);
    }
    return b;
  }
  if (kind == "obox") {
    if (!numbers || v.size() != 9)
      fail(text, "expected an oriented box as obox:CX,CY,CZ,SX,SY,SZ,AX,AY,AZ (centre and sizes in mm, rotation "
                 "about x, y, z in degrees)");
    checkRange(6);
    if (!(float(v[3]) > 0 && float(v[4]) > 0 && float(v[5]) > 0)) fail(text, "an oriented box's sizes must be > 0 mm");
    // R = Rz Ry Rx: the box's axes are R's columns.
    glm::dmat4 r(1.0);
    r = glm::rotate(r, glm::radians(v[8]), glm::dvec3(0, 0, 1));
    r = glm::rotate(r, glm::radians(v[7]), glm::dvec3(0, 1, 0));
    r = glm::rotate(r, glm::radians(v[6]), glm::dvec3(1, 0, 0));
    OrientedBoxRegion o;
    o.center = {v[0], v[1], v[2]};
    o.angles_deg = {v[6], v[7], v[8]};
    for (int k = 0; k < 3; ++k) {
      o.axes[k] = {r[k][0], r[k][1], r[k][2]};
      o.half[k] = v[3 + k] / 2;
    }
    return o;
  }
  fail(text, "unknown region kind '" + std::string(kind) + "' (expected sphere:, box:, obox: or mask:)");
}

std::string regionSpec(const Region& region) {
  if (const auto* s = std::get_if<SphereRegion>(&region))
    return "sphere:" + number(s->center[0]) + "," + number(s->center[1]) + "," + number(s->center[2]) + "," +
           number(s->radius);
  if (const auto* b = std::get_if<BoxRegion>(&region))
    return "box:" + number(b->min[0]) + "," + number(b->min[1]) + "," + number(b->min[2]) + "," + number(b->max[0]) +
           "," + number(b->max[1]) + "," + number(b->max[2]);
  if (const auto* m = std::get_if<MaskRegion>(&region)) return "mask:" + m->path;
  const auto& o = std::get<OrientedBoxRegion>(region);
  std::string out = "obox:";
  for (const double x : {o.center[0], o.center[1], o.center[2], 2 * o.half[0], 2 * o.half[1], 2 * o.half[2],
                         o.angles_deg[0], o.angles_deg[1], o.angles_deg[2]})
    out += (out.size() > 5 ? "," : "") + number(x);
  return out;
}

}  // namespace fibscope
