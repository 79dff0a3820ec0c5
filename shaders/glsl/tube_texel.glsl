// The surface texel of a ray-cast tube hit, written alike by the compute
// caster (tube_raycast.comp) and the fragment-shader caster's resolve
// (tube_raster_resolve.comp), so both variants give the same texels:
// depth, fiber, normal, tangent, position along the fiber, the colour
// interpolated between the nodes.
#ifndef FIBSCOPE_GLSL_TUBE_TEXEL_GLSL
#define FIBSCOPE_GLSL_TUBE_TEXEL_GLSL

#include "shared/gbuffer.h"
#include "shared/tubes.h"
#include "glsl/tangent.glsl"
#include "glsl/tube_intersect.glsl"

// Colour of node n as RGBA in [0, 1] and its slope per mm.
vec4 tubeNodeColor(TubeNode n) { return unpackUnorm4x8(n.color); }
vec4 tubeNodeColorSlope(TubeNode n) { return unpackSnorm4x8(n.color_slope) * kTubeColorSlopeMax; }

// Sub-segment `item` of segment s (nodes a, b) hit at world point `hit`,
// sub-segment parameter t, clip depth `depth`.
SurfaceTexel tubeSurfaceTexel(TubeSegment s, TubeNode a, TubeNode b, uint item, vec3 hit, float t, float depth) {
  const uint which_half = item % 2u;
  const TubeQuadratic q = tubeQuadratic(a, b, s.chord, which_half);
  // Position along the segment, u in [0, 1]: the halves split it at 1/2.
  const float u = 0.5 * (float(which_half) + t);
  SurfaceTexel texel;
  texel.depth = depth;
  texel.fiber = s.fiber;
  texel.normal = packSegmentTangent(hit - tubeQuadraticCenter(q, t));
  // The centre line's direction; a one-point tube (a sphere, no
  // direction) takes its normal, as sphere_surface.comp does.
  const vec3 dq = tubeQuadraticDerivative(q, t);
  texel.tangent = dot(dq, dq) > 0.0 ? packSegmentTangent(dq) : texel.normal;
  texel.position = mix(a.point, b.point, u);
  texel.color = 0u;
  if (a.color >> 24 != 0u || b.color >> 24 != 0u) {
    // Hermite in the colour, slopes per mm times the chord.
    const float u2 = u * u, u3 = u2 * u;
    const vec4 col = (2.0 * u3 - 3.0 * u2 + 1.0) * tubeNodeColor(a) +
                     (u3 - 2.0 * u2 + u) * s.chord * tubeNodeColorSlope(a) + (-2.0 * u3 + 3.0 * u2) * tubeNodeColor(b) +
                     (u3 - u2) * s.chord * tubeNodeColorSlope(b);
    texel.color = packUnorm4x8(vec4(clamp(col.rgb, 0.0, 1.0), 1.0));
  }
  texel.source = kSurfaceSourceTube;
  texel.pad0 = 0u;
  return texel;
}

#endif
