// The tessellated tube's surface (shared/tube_tess.h; seed section 3.1),
// evaluated alike by the control stage (corners, for the levels and the
// culling) and the evaluation stage (every vertex): the Hermite centre
// line, radius, and the cross-section frame interpolated from the nodes'
// rotation-minimising normals (TubeNode::normal, src/tubes/tube_frames.h),
// so rings never twist.
//
// At u = 0 and u = 1 every value is the node's own, bit for bit (selected,
// not interpolated): the end ring of a segment and the start ring of the
// next are the same vertices, so joined segments have no cracks.
#ifndef FIBSCOPE_GLSL_TUBE_TESS_GLSL
#define FIBSCOPE_GLSL_TUBE_TESS_GLSL

#include "shared/tubes.h"
#include "shared/tube_tess.h"
#include "glsl/tangent.glsl"

const float kTubeTessPi = 3.14159265358979;

struct TubeTessSegment {
  TubeNode a, b;
  TubeSegment s;
  vec3 n0, n1;  // the nodes' frame normals
};

TubeTessSegment tubeTessSegment(TubeSegment s, TubeNode a, TubeNode b) {
  TubeTessSegment t;
  t.a = a;
  t.b = b;
  t.s = s;
  t.n0 = unpackTangent(a.normal);
  t.n1 = unpackTangent(b.normal);
  return t;
}

vec3 tubeTessCenter(TubeTessSegment g, float u) {
  const vec3 p0 = g.a.position_radius.xyz, p1 = g.b.position_radius.xyz;
  if (u <= 0.0) return p0;
  if (u >= 1.0) return p1;
  const vec3 m0 = g.s.chord * g.a.tangent_dradius.xyz, m1 = g.s.chord * g.b.tangent_dradius.xyz;
  const float u2 = u * u, u3 = u2 * u;
  return (2.0 * u3 - 3.0 * u2 + 1.0) * p0 + (u3 - 2.0 * u2 + u) * m0 + (-2.0 * u3 + 3.0 * u2) * p1 + (u3 - u2) * m1;
}

float tubeTessRadius(TubeTessSegment g, float u) {
  const float r0 = g.a.position_radius.w, r1 = g.b.position_radius.w;
  if (u <= 0.0) return r0;
  if (u >= 1.0) return r1;
  const float m0 = g.s.chord * g.a.tangent_dradius.w, m1 = g.s.chord * g.b.tangent_dradius.w;
  const float u2 = u * u, u3 = u2 * u;
  return max((2.0 * u3 - 3.0 * u2 + 1.0) * r0 + (u3 - 2.0 * u2 + u) * m0 + (-2.0 * u3 + 3.0 * u2) * r1 + (u3 - u2) * m1,
             0.0);
}

// The unit tangent of the centre line (the node's at the ends; a segment of
// chord 0, a one-point tube's, takes the first node's).
vec3 tubeTessTangent(TubeTessSegment g, float u) {
  const vec3 t0 = normalize(g.a.tangent_dradius.xyz), t1 = normalize(g.b.tangent_dradius.xyz);
  if (u <= 0.0 || g.s.chord <= 0.0) return t0;
  if (u >= 1.0) return t1;
  const vec3 p0 = g.a.position_radius.xyz, p1 = g.b.position_radius.xyz;
  const vec3 m0 = g.s.chord * g.a.tangent_dradius.xyz, m1 = g.s.chord * g.b.tangent_dradius.xyz;
  const float u2 = u * u;
  const vec3 d = (6.0 * u2 - 6.0 * u) * (p0 - p1) + (3.0 * u2 - 4.0 * u + 1.0) * m0 + (3.0 * u2 - 2.0 * u) * m1;
  return dot(d, d) > 0.0 ? normalize(d) : mix(t0, t1, u);
}

// Unit radial direction at u, turn fraction `around` in [0, 1): the
// frame's normal is the nodes' normals interpolated and made normal to the
// tangent (the propagated frames differ by the rotation-minimising motion
// only, so the interpolation adds no twist), the binormal T x N.
vec3 tubeTessRadial(TubeTessSegment g, float u, vec3 tangent, float around) {
  vec3 n = u <= 0.0 ? g.n0 : (u >= 1.0 ? g.n1 : g.n0 * (1.0 - u) + g.n1 * u);
  n -= dot(n, tangent) * tangent;
  n = dot(n, n) > 1e-12 ? normalize(n) : g.n0;
  const vec3 b = cross(tangent, n);
  const float phi = 2.0 * kTubeTessPi * around;
  return cos(phi) * n + sin(phi) * b;
}

// Turn fraction of corner `k` (0 .. vertices) around: the last corner is
// the first one's, exactly.
float tubeTessAround(uint k, uint vertices) { return k >= vertices ? 0.0 : float(k) / float(vertices); }

// A point of the body at u and of a cap: `cap` -1 (start) or +1 (end),
// latitude fraction `lat` in [0, 1] from the seam to the pole. `radial`
// is the seam ring's direction there; lat = 0 gives the ring's own point.
vec3 tubeTessBodyPoint(TubeTessSegment g, float u, float around, out vec3 radial) {
  radial = tubeTessRadial(g, u, tubeTessTangent(g, u), around);
  // precise: the same bits wherever the point is evaluated (no contraction
  // that may differ between the stages' inlined copies).
  precise vec3 p = tubeTessCenter(g, u) + tubeTessRadius(g, u) * radial;
  return p;
}

vec3 tubeTessCapPoint(TubeTessSegment g, float cap, float around, float lat, out vec3 normal) {
  const float u = cap < 0.0 ? 0.0 : 1.0;
  if (lat <= 0.0) return tubeTessBodyPoint(g, u, around, normal);  // the seam: the body's end ring
  const vec3 t = tubeTessTangent(g, u);
  const vec3 radial = tubeTessRadial(g, u, t, around);
  const float theta = 0.5 * kTubeTessPi * lat;
  normal = lat >= 1.0 ? cap * t : cos(theta) * radial + sin(theta) * (cap * t);
  return tubeTessCenter(g, u) + tubeTessRadius(g, u) * normal;
}

#endif
