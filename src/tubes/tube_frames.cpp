#include "tubes/tube_frames.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "tubes/tube_model.h"

namespace fibscope {

glm::vec3 doubleReflection(const glm::vec3& x0, const glm::vec3& t0, const glm::vec3& r0, const glm::vec3& x1,
                           const glm::vec3& t1) {
  // Reflection R1 in the plane bisecting x0 x1 maps (x0, t0, r0) to x1;
  // reflection R2 in the plane bisecting the reflected tangent and t1 then
  // aligns the tangents (Wang et al. 2008, algorithm "double reflection").
  const glm::vec3 v1 = x1 - x0;
  const float c1 = glm::dot(v1, v1);
  glm::vec3 r_l = r0, t_l = t0;
  if (c1 > 0.0f) {
    r_l = r0 - (2.0f / c1) * glm::dot(v1, r0) * v1;
    t_l = t0 - (2.0f / c1) * glm::dot(v1, t0) * v1;
  }
  const glm::vec3 v2 = t1 - t_l;
  const float c2 = glm::dot(v2, v2);
  glm::vec3 r1 = c2 > 0.0f ? r_l - (2.0f / c2) * glm::dot(v2, r_l) * v2 : r_l;
  // Reflections keep lengths and angles; re-orthogonalise against float
  // drift over a tube of 10^5 nodes.
  r1 -= glm::dot(r1, t1) * t1;
  const float l = glm::length(r1);
  return l > 0.0f ? r1 / l : anyNormal(t1);
}

glm::vec3 anyNormal(const glm::vec3& t) {
  // Cross with the axis least aligned with t: never near-parallel.
  const glm::vec3 a = std::fabs(t.x) <= std::fabs(t.y) && std::fabs(t.x) <= std::fabs(t.z) ? glm::vec3(1, 0, 0)
                      : std::fabs(t.y) <= std::fabs(t.z)                                   ? glm::vec3(0, 1, 0)
                                                                                           : glm::vec3(0, 0, 1);
  return glm::normalize(glm::cross(t, a));
}

size_t propagateTubeFrames(shader::TubeNode* nodes, const shader::TubeSegment* segments, size_t count,
                           float substep_degrees, const glm::vec3* start) {
  if (count == 0) return 0;
  const auto position = [&](size_t i) {
    return glm::vec3(nodes[i].position_radius.x, nodes[i].position_radius.y, nodes[i].position_radius.z);
  };
  const auto tangent = [&](size_t i) {
    return glm::vec3(nodes[i].tangent_dradius.x, nodes[i].tangent_dradius.y, nodes[i].tangent_dradius.z);
  };
  glm::vec3 r = start ? *start : anyNormal(tangent(0));
  nodes[0].normal = packUnitVector(r);
  const float cos_limit = std::cos(glm::radians(std::max(substep_degrees, 1.0f)));
  size_t extra = 0;
  for (size_t i = 0; i + 1 < count; ++i) {
    const glm::vec3 x0 = position(i), x1 = position(i + 1), t0 = tangent(i), t1 = tangent(i + 1);
    const float c = std::clamp(glm::dot(t0, t1), -1.0f, 1.0f);
    if (c >= cos_limit) {
      r = doubleReflection(x0, t0, r, x1, t1);
    } else {
      // Sub-steps along the Hermite curve, its own tangents in between.
      const size_t steps = size_t(std::ceil(std::acos(c) / std::acos(cos_limit)));
      const float length = segments[i].chord;
      const glm::vec3 m0 = length * t0, m1 = length * t1;
      glm::vec3 xa = x0, ta = t0;
      for (size_t k = 1; k <= steps; ++k) {
        const float u = float(k) / float(steps);
        glm::vec3 xb = x1, tb = t1;
        if (k < steps) {
          xb = hermitePoint(x0, m0, x1, m1, u);
          const glm::vec3 d = hermiteDerivative(x0, m0, x1, m1, u);
          const float l = glm::length(d);
          tb = l > 0.0f ? d / l : ta;
        }
        r = doubleReflection(xa, ta, r, xb, tb);
        xa = xb;
        ta = tb;
      }
      extra += steps - 1;
    }
    nodes[i + 1].normal = packUnitVector(r);
  }
  return extra;
}

}  // namespace fibscope
