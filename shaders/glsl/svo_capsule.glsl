// Straight capsules of the tube model's segments (shared/svo.h): their
// ends and radius, the signed distance (seed eq. 1) and the exact front
// intersection with a ray; CPU twins in src/svo/svo_build.h.
#ifndef FIBSCOPE_GLSL_SVO_CAPSULE_GLSL
#define FIBSCOPE_GLSL_SVO_CAPSULE_GLSL

struct SvoCapsuleF {
  vec3 a;
  vec3 b;
  float r;
};

SvoCapsuleF svoCapsuleOf(TubeNode na, TubeNode nb) {
  SvoCapsuleF c;
  c.a = na.position_radius.xyz;
  c.b = nb.position_radius.xyz;
  c.r = 0.5 * (na.position_radius.w + nb.position_radius.w);
  return c;
}

float svoCapsuleDistance(SvoCapsuleF c, vec3 p) {
  const vec3 ba = c.b - c.a, pa = p - c.a;
  const float baba = dot(ba, ba);
  const float h = baba > 0.0 ? clamp(dot(pa, ba) / baba, 0.0, 1.0) : 0.0;
  return length(pa - h * ba) - c.r;
}

// Front hit t > t_min of o + t d (|d| = 1): the two end spheres (stable
// form) and the cylinder side solved from the ray's closest approach to a
// (so the quadratic's terms are of the tube's size, not the eye's
// distance). A zero-length segment is its sphere.
bool svoIntersectCapsule(SvoCapsuleF c, vec3 o, vec3 d, float t_min, out float t) {
  float best = 1e30;
  for (uint k = 0u; k < 2u; ++k) {
    const vec3 oc = (k == 0u ? c.a : c.b) - o;
    const float bq = dot(oc, d);
    const vec3 h = oc - bq * d;
    const float disc = c.r * c.r - dot(h, h);
    if (disc >= 0.0) {
      const float s = bq - sqrt(disc);
      if (s > t_min && s < best) best = s;
    }
  }
  const vec3 ba = c.b - c.a;
  const float len = length(ba);
  if (len > 0.0) {
    const vec3 u = ba / len;
    const float tc = dot(c.a - o, d);
    const vec3 oa = (o - c.a) + tc * d;
    const vec3 op = oa - dot(oa, u) * u, dp = d - dot(d, u) * u;
    const float A = dot(dp, dp), B = dot(op, dp), C = dot(op, op) - c.r * c.r;
    const float disc = B * B - A * C;
    if (A > 0.0 && disc >= 0.0) {
      const float s = (-B - sqrt(disc)) / A;
      const float y = dot(oa, u) + s * dot(d, u);
      if (y >= 0.0 && y <= len && tc + s > t_min && tc + s < best) best = tc + s;
    }
  }
  t = best;
  return best < 1e30;
}

// t of the ray o + t d's (|d| = 1) closest approach to the segment [a, b]
// (the level of detail's hit where the ray misses the capsule): from the
// components perpendicular to d, so a far eye's distance cancels before
// the division; a segment parallel to the ray (or of zero length) by its
// middle.
float svoRayClosestApproach(SvoCapsuleF c, vec3 o, vec3 d) {
  const vec3 ba = c.b - c.a, w = o - c.a;
  const float wd = dot(w, d), bd = dot(ba, d);
  const vec3 wp = w - wd * d, bp = ba - bd * d;
  const float bpbp = dot(bp, bp);
  const float s = bpbp > 1e-12 * max(dot(ba, ba), 1e-30) ? clamp(dot(wp, bp) / bpbp, 0.0, 1.0) : 0.5;
  return s * bd - wd;
}

#endif
