// Ray against one sphere-swept quadratic sub-segment (shared/tubes.h
// TubeQuadratic): the bisection cascade of src/tubes/tube_intersect.h, in
// float (the header describes the algorithm: the roots of the quartic
// g(t) = r^2 - |h|^2 by 7 searches of 10 bisections, then the minimum of
// the front distance f(t) = z(t) - sqrt(g(t)) on each interval of g >= 0),
// and the sub-segment's box. Its CPU reference is intersectTubeQuadratic.
#ifndef FIBSCOPE_GLSL_TUBE_INTERSECT_GLSL
#define FIBSCOPE_GLSL_TUBE_INTERSECT_GLSL

#include "shared/tubes.h"

const int kTubeBisections = 10;
const int kTubeMinimumSamples = 4;
const int kTubeMaxBreaks = 16;

// The ray's polynomials: g (degree 4), g' (3), and z = (c - o).d (2).
struct TubeRayPoly {
  float g[5];
  float g1[4];
  vec3 z;  // z(t) = z.x t^2 + z.y t + z.z
};

float tubeG(TubeRayPoly p, float t) { return (((p.g[4] * t + p.g[3]) * t + p.g[2]) * t + p.g[1]) * t + p.g[0]; }
float tubeG1(TubeRayPoly p, float t) { return ((p.g1[3] * t + p.g1[2]) * t + p.g1[1]) * t + p.g1[0]; }
float tubeF(TubeRayPoly p, float t) { return (p.z.x * t + p.z.y) * t + p.z.z - sqrt(max(tubeG(p, t), 0.0)); }
// Has the sign of f'(t) where g > 0.
float tubePhi(TubeRayPoly p, float t) {
  return 2.0 * (2.0 * p.z.x * t + p.z.y) * sqrt(max(tubeG(p, t), 0.0)) - tubeG1(p, t);
}
// which: 0 g', 1 g, 2 phi.
float tubeEval(TubeRayPoly p, int which, float t) {
  return which == 0 ? tubeG1(p, t) : (which == 1 ? tubeG(p, t) : tubePhi(p, t));
}

float tubeBisect(TubeRayPoly p, int which, float lo, float hi) {
  const bool lo_negative = tubeEval(p, which, lo) < 0.0;
  for (int i = 0; i < kTubeBisections; ++i) {
    const float mid = 0.5 * (lo + hi);
    if ((tubeEval(p, which, mid) < 0.0) == lo_negative)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

// The breakpoints b[0 .. n) (sorted, from 0 to 1) with the roots of the
// function `which` inserted, which is monotone between them.
void tubeMonotoneRoots(TubeRayPoly p, int which, inout float b[kTubeMaxBreaks], inout int n) {
  float o[kTubeMaxBreaks];
  int m = 0;
  o[m++] = 0.0;
  for (int i = 0; i + 1 < n; ++i) {
    const float a = b[i], c = b[i + 1];
    if ((tubeEval(p, which, a) < 0.0) != (tubeEval(p, which, c) < 0.0) && m < kTubeMaxBreaks - 1)
      o[m++] = tubeBisect(p, which, a, c);
    if (i + 2 < n && m < kTubeMaxBreaks - 1) o[m++] = c;
  }
  o[m++] = 1.0;
  b = o;
  n = m;
}

// The front hit of the ray o + s d (d unit) with s > 0: true, s and the
// sub-segment parameter t of the sphere hit.
bool tubeIntersect(TubeQuadratic q, vec3 o, vec3 d, out float s_out, out float t_out) {
  s_out = 0.0;
  t_out = 0.0;
  const vec3 A = q.b0.xyz - 2.0 * q.b1.xyz + q.b2.xyz, B = 2.0 * (q.b1.xyz - q.b0.xyz), C = q.b0.xyz - o;
  const float ra = q.b0.w - 2.0 * q.b1.w + q.b2.w, rb = 2.0 * (q.b1.w - q.b0.w), rc = q.b0.w;
  TubeRayPoly p;
  p.z = vec3(dot(A, d), dot(B, d), dot(C, d));
  const vec3 Ap = A - p.z.x * d, Bp = B - p.z.y * d, Cp = C - p.z.z * d;
  p.g[0] = rc * rc - dot(Cp, Cp);
  p.g[1] = 2.0 * rb * rc - 2.0 * dot(Bp, Cp);
  p.g[2] = rb * rb + 2.0 * ra * rc - dot(Bp, Bp) - 2.0 * dot(Ap, Cp);
  p.g[3] = 2.0 * ra * rb - 2.0 * dot(Ap, Bp);
  p.g[4] = ra * ra - dot(Ap, Ap);
  for (int i = 0; i < 4; ++i) p.g1[i] = float(i + 1) * p.g[i + 1];
  const vec3 g2 = vec3(p.g1[1], 2.0 * p.g1[2], 3.0 * p.g1[3]);  // g'' = g2.x + g2.y t + g2.z t^2

  // 1. The cascade: g'' in closed form, then g', then g.
  float b[kTubeMaxBreaks];
  int n = 0;
  b[n++] = 0.0;
  if (g2.z != 0.0) {
    const float disc = g2.y * g2.y - 4.0 * g2.z * g2.x;
    if (disc >= 0.0) {
      const float sq = sqrt(disc);
      const float k = -0.5 * (g2.y + (g2.y >= 0.0 ? sq : -sq));
      float r0 = k / g2.z, r1 = k != 0.0 ? g2.x / k : -1.0;
      if (r0 > r1) {
        const float tmp = r0;
        r0 = r1;
        r1 = tmp;
      }
      if (r0 > 0.0 && r0 < 1.0) b[n++] = r0;
      if (r1 > 0.0 && r1 < 1.0 && r1 != r0) b[n++] = r1;
    }
  } else if (g2.y != 0.0) {
    const float r = -g2.x / g2.y;
    if (r > 0.0 && r < 1.0) b[n++] = r;
  }
  b[n++] = 1.0;
  tubeMonotoneRoots(p, 0, b, n);
  tubeMonotoneRoots(p, 1, b, n);

  // 2. The front of f on each interval where g >= 0.
  float best = 3.4e38;
  bool found = false;
  for (int i = 0; i + 1 < n; ++i) {
    const float a = b[i], c = b[i + 1];
    if (tubeG(p, 0.5 * (a + c)) < 0.0) continue;
    float cand[kTubeMinimumSamples + 2];
    int m = 0;
    if (a == 0.0) cand[m++] = 0.0;
    if (c == 1.0) cand[m++] = 1.0;
    float prev_t = a, prev_phi = tubePhi(p, a);
    for (int k = 1; k <= kTubeMinimumSamples; ++k) {
      const float t = a + (c - a) * float(k) / float(kTubeMinimumSamples);
      const float phi = tubePhi(p, t);
      if (prev_phi < 0.0 && phi >= 0.0 && m < kTubeMinimumSamples + 2) cand[m++] = tubeBisect(p, 2, prev_t, t);
      prev_t = t;
      prev_phi = phi;
    }
    for (int j = 0; j < m; ++j) {
      if (tubeG(p, cand[j]) < 0.0) continue;
      const float s = tubeF(p, cand[j]);
      if (s > 0.0 && s < best) {
        best = s;
        t_out = cand[j];
        found = true;
      }
    }
  }
  s_out = best;
  return found;
}

vec3 tubeQuadraticCenter(TubeQuadratic q, float t) {
  return (1.0 - t) * (1.0 - t) * q.b0.xyz + 2.0 * t * (1.0 - t) * q.b1.xyz + t * t * q.b2.xyz;
}
vec3 tubeQuadraticDerivative(TubeQuadratic q, float t) {
  return 2.0 * (1.0 - t) * (q.b1.xyz - q.b0.xyz) + 2.0 * t * (q.b2.xyz - q.b1.xyz);
}

// The sub-segment's box: the centre curve's exact extent per axis (the
// quadratic's extremum where its derivative vanishes inside (0, 1)),
// widened by the largest radius control (the radius never exceeds it).
void tubeBox(TubeQuadratic q, out vec3 lo, out vec3 hi) {
  lo = min(q.b0.xyz, q.b2.xyz);
  hi = max(q.b0.xyz, q.b2.xyz);
  const vec3 den = q.b0.xyz - 2.0 * q.b1.xyz + q.b2.xyz;
  for (int k = 0; k < 3; ++k) {
    if (den[k] == 0.0) continue;
    const float t = (q.b0[k] - q.b1[k]) / den[k];
    if (t > 0.0 && t < 1.0) {
      const float v = (1.0 - t) * (1.0 - t) * q.b0[k] + 2.0 * t * (1.0 - t) * q.b1[k] + t * t * q.b2[k];
      lo[k] = min(lo[k], v);
      hi[k] = max(hi[k], v);
    }
  }
  const float r = max(max(q.b0.w, q.b1.w), q.b2.w);
  lo -= vec3(r);
  hi += vec3(r);
}

// Whether the ray o + s d (s > 0) meets the box; `enter`: the s at which
// it enters (0 from inside).
bool tubeRayEntersBox(vec3 lo, vec3 hi, vec3 o, vec3 inv_d, out float enter) {
  const vec3 t0 = (lo - o) * inv_d, t1 = (hi - o) * inv_d;
  const vec3 tn = min(t0, t1), tf = max(t0, t1);
  enter = max(max(tn.x, tn.y), max(tn.z, 0.0));
  const float leave = min(min(tf.x, tf.y), tf.z);
  return enter <= leave;
}

#endif
