// The tight oriented box of a quadratic sub-segment (seed figure 17;
// shared/tubes.h TubeQuadratic), the GLSL twin of src/tubes/tube_bounds.h
// (which says how it is built and is tested against the swept surface).
#ifndef FIBSCOPE_GLSL_TUBE_BOX_GLSL
#define FIBSCOPE_GLSL_TUBE_BOX_GLSL

#include "shared/tubes.h"

// The range of the quadratic Bezier with controls u0, u1, u2 over [0, 1].
void tubeBezierRange(float u0, float u1, float u2, inout float lo, inout float hi) {
  lo = min(lo, min(u0, u2));
  hi = max(hi, max(u0, u2));
  const float den = u0 - 2.0 * u1 + u2;
  if (den != 0.0) {
    const float t = (u0 - u1) / den;
    if (t > 0.0 && t < 1.0) {
      const float v = (1.0 - t) * (1.0 - t) * u0 + 2.0 * t * (1.0 - t) * u1 + t * t * u2;
      lo = min(lo, v);
      hi = max(hi, v);
    }
  }
}

// The box: world point p is inside when lo <= transpose(axes) (p - q.b0.xyz)
// <= hi (axes orthonormal, columns x, y, z). lo > hi on some axis: empty
// (every radius control <= 0).
void tubeOrientedBox(TubeQuadratic q, out mat3 axes, out vec3 lo, out vec3 hi) {
  const vec3 e1 = q.b1.xyz - q.b0.xyz, e2 = q.b2.xyz - q.b0.xyz;
  const float rmax = max(max(q.b0.w, q.b1.w), q.b2.w);
  const float scale = max(max(length(e1), length(e2)), max(rmax, 0.0));
  const float tiny = 1e-12 * scale * scale;
  vec3 x = vec3(1.0, 0.0, 0.0);
  if (dot(e2, e2) > tiny && dot(e2, e2) > 0.0)
    x = normalize(e2);
  else if (dot(e1, e1) > tiny && dot(e1, e1) > 0.0)
    x = normalize(e1);
  vec3 w = e1 - dot(e1, x) * x;
  if (!(dot(w, w) > tiny && dot(w, w) > 0.0)) w = cross(x, abs(x.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0));
  const vec3 y = normalize(w);
  const vec3 z = cross(x, y);
  axes = mat3(x, y, z);
  lo = vec3(3.4e38);
  hi = vec3(-3.4e38);
  for (int k = 0; k < 3; ++k) {
    const vec3 a = axes[k];
    const float u1 = dot(e1, a), u2 = dot(e2, a);
    float l = 3.4e38, h = -3.4e38, l2 = 3.4e38, h2 = -3.4e38;
    tubeBezierRange(-q.b0.w, u1 - q.b1.w, u2 - q.b2.w, l, h2);
    tubeBezierRange(q.b0.w, u1 + q.b1.w, u2 + q.b2.w, l2, h);
    lo[k] = l;
    hi[k] = h;
  }
  // Float slack: rounding in the axes and the dot products.
  const float pad = 1e-4 * max(rmax, 0.0) + 1e-6 * (scale + length(q.b0.xyz));
  lo -= vec3(pad);
  hi += vec3(pad);
}

#endif
