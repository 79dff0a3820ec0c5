// Curved tubes of the tube model's segments (shared/svo.h, svo-curved):
// the cubic Hermite centre line (ends, end derivatives chord * tangent),
// the radius of the capsule (the mean of the node radii), the signed
// distance by nearest point (sampled, then Newton), and the box of the
// Bezier control points; CPU twins in src/svo/svo_build.h (svoCurve,
// curveDistance, curveBounds).
#ifndef FIBSCOPE_GLSL_SVO_CURVE_GLSL
#define FIBSCOPE_GLSL_SVO_CURVE_GLSL

struct SvoCurveF {
  vec3 p0;
  vec3 m0;
  vec3 p1;
  vec3 m1;
  float r;
};

SvoCurveF svoCurveOf(TubeNode na, TubeNode nb, float chord) {
  SvoCurveF c;
  c.p0 = na.position_radius.xyz;
  c.p1 = nb.position_radius.xyz;
  c.m0 = chord * na.tangent_dradius.xyz;
  c.m1 = chord * nb.tangent_dradius.xyz;
  c.r = 0.5 * (na.position_radius.w + nb.position_radius.w);
  return c;
}

vec3 svoCurvePoint(SvoCurveF c, float u) {
  const float u2 = u * u, u3 = u2 * u;
  return (2.0 * u3 - 3.0 * u2 + 1.0) * c.p0 + (u3 - 2.0 * u2 + u) * c.m0 + (-2.0 * u3 + 3.0 * u2) * c.p1 +
         (u3 - u2) * c.m1;
}

vec3 svoCurveDerivative(SvoCurveF c, float u) {
  const float u2 = u * u;
  return (6.0 * u2 - 6.0 * u) * c.p0 + (3.0 * u2 - 4.0 * u + 1.0) * c.m0 + (-6.0 * u2 + 6.0 * u) * c.p1 +
         (3.0 * u2 - 2.0 * u) * c.m1;
}

// |p - C(u*)| - r; u* the nearest point's parameter.
float svoCurveDistance(SvoCurveF c, vec3 p, out float u_out) {
  float best_u = 0.0, best = 1e30;
  for (uint k = 0u; k <= kSvoCurveSamples; ++k) {
    const float u = float(k) / float(kSvoCurveSamples);
    const vec3 e = svoCurvePoint(c, u) - p;
    const float d2 = dot(e, e);
    if (d2 < best) {
      best = d2;
      best_u = u;
    }
  }
  float u = best_u;
  for (uint it = 0u; it < kSvoCurveNewtonSteps; ++it) {
    const vec3 e = svoCurvePoint(c, u) - p;
    const vec3 d1 = svoCurveDerivative(c, u);
    const vec3 d2 = (12.0 * u - 6.0) * c.p0 + (6.0 * u - 4.0) * c.m0 + (6.0 - 12.0 * u) * c.p1 + (6.0 * u - 2.0) * c.m1;
    const float g = dot(e, d1), h = dot(d1, d1) + dot(e, d2);
    if (!(h > 0.0)) break;
    u = clamp(u - g / h, 0.0, 1.0);
  }
  const vec3 e = svoCurvePoint(c, u) - p;
  float d2 = dot(e, e);
  if (!(d2 <= best)) {
    d2 = best;
    u = best_u;
  }
  u_out = u;
  return sqrt(d2) - c.r;
}

void svoCurveBounds(SvoCurveF c, out vec3 lo, out vec3 hi) {
  const vec3 b1 = c.p0 + c.m0 / 3.0, b2 = c.p1 - c.m1 / 3.0;
  lo = min(min(c.p0, c.p1), min(b1, b2));
  hi = max(max(c.p0, c.p1), max(b1, b2));
}

#endif
