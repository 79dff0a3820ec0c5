#include "tubes/tube_bounds.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace fibscope {
namespace {

// The range of the quadratic Bezier with controls u0, u1, u2 over [0, 1].
void bezierRange(float u0, float u1, float u2, float& lo, float& hi) {
  lo = std::min(lo, std::min(u0, u2));
  hi = std::max(hi, std::max(u0, u2));
  const float den = u0 - 2.0f * u1 + u2;
  if (den != 0.0f) {
    const float t = (u0 - u1) / den;
    if (t > 0.0f && t < 1.0f) {
      const float v = (1.0f - t) * (1.0f - t) * u0 + 2.0f * t * (1.0f - t) * u1 + t * t * u2;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
}

glm::vec3 xyz(const shader::vec4& v) { return {v.x, v.y, v.z}; }

}  // namespace

bool TubeOrientedBox::contains(const glm::vec3& p, float slack) const {
  const glm::vec3 l = glm::transpose(axes) * (p - origin);
  for (int k = 0; k < 3; ++k)
    if (l[k] < lo[k] - slack || l[k] > hi[k] + slack) return false;
  return true;
}

float TubeOrientedBox::volume() const {
  const glm::vec3 e = glm::max(hi - lo, glm::vec3(0.0f));
  return e.x * e.y * e.z;
}

TubeOrientedBox tubeOrientedBox(const shader::TubeQuadratic& q) {
  TubeOrientedBox box;
  box.origin = xyz(q.b0);
  const glm::vec3 e1 = xyz(q.b1) - box.origin, e2 = xyz(q.b2) - box.origin;
  const float rmax = std::max({q.b0.w, q.b1.w, q.b2.w});
  const float scale = std::max({glm::length(e1), glm::length(e2), std::max(rmax, 0.0f)});
  const float tiny = 1e-12f * scale * scale;
  glm::vec3 x(1.0f, 0.0f, 0.0f);
  if (glm::dot(e2, e2) > tiny && glm::dot(e2, e2) > 0.0f)
    x = glm::normalize(e2);
  else if (glm::dot(e1, e1) > tiny && glm::dot(e1, e1) > 0.0f)
    x = glm::normalize(e1);
  glm::vec3 w = e1 - glm::dot(e1, x) * x;
  if (!(glm::dot(w, w) > tiny && glm::dot(w, w) > 0.0f))
    w = glm::cross(x, std::fabs(x.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f));
  const glm::vec3 y = glm::normalize(w);
  box.axes = glm::mat3(x, y, glm::cross(x, y));
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 a = box.axes[k];
    const float u1 = glm::dot(e1, a), u2 = glm::dot(e2, a);
    float lo = 3.4e38f, hi = -3.4e38f, unused_lo = 3.4e38f, unused_hi = -3.4e38f;
    bezierRange(-q.b0.w, u1 - q.b1.w, u2 - q.b2.w, lo, unused_hi);
    bezierRange(q.b0.w, u1 + q.b1.w, u2 + q.b2.w, unused_lo, hi);
    box.lo[k] = lo;
    box.hi[k] = hi;
  }
  const float pad = 1e-4f * std::max(rmax, 0.0f) + 1e-6f * (scale + glm::length(box.origin));
  box.lo -= glm::vec3(pad);
  box.hi += glm::vec3(pad);
  return box;
}

void tubeAxisAlignedBox(const shader::TubeQuadratic& q, glm::vec3& lo, glm::vec3& hi) {
  const glm::vec3 b0 = xyz(q.b0), b1 = xyz(q.b1), b2 = xyz(q.b2);
  lo = glm::min(b0, b2);
  hi = glm::max(b0, b2);
  for (int k = 0; k < 3; ++k) bezierRange(b0[k], b1[k], b2[k], lo[k], hi[k]);
  const float r = std::max({q.b0.w, q.b1.w, q.b2.w});
  lo -= glm::vec3(r);
  hi += glm::vec3(r);
}

}  // namespace fibscope
