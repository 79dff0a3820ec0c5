// Spline tubes by adaptive tessellation, evaluation stage (shared/tube_tess.h;
// seed section 3.1, figures 6 and 7): the vertex at (around, along) of its
// patch on the Hermite tube (glsl/tube_tess.glsl: centre, radius and the
// interpolated rotation-minimising frame), or on a hemispherical cap.
// The body's normal is the offset from the centre projected on the plane
// normal to the surface's own tangent along the tube, taken by central
// differences of the surface (figure 7), so a varying radius tilts it as
// it tilts the surface; a cap's is its sphere's. Radius, colour and the
// position along the fiber are interpolated along the tube.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tube_tess.h"
#include "shared/tubes.h"
#define SHADE_COMMON_NO_TILES  // graphics stage: no workgroup built-ins
#include "glsl/shade_common.glsl"
#include "glsl/tube_tess.glsl"

layout(quads, equal_spacing, ccw) in;

layout(push_constant, std430) uniform Push { TubeTessPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };

layout(location = 0) patch in uint patch_index;

// The frame's clip planes clip the triangles exactly (surface_cuts.glsl's
// rule for the planes; mesh cuts in tube_tess.frag).
out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[kMaxFrameClipPlanes];
};

layout(location = 0) out vec3 out_normal;
layout(location = 1) out vec3 out_tangent;  // 0: none (a one-point tube)
layout(location = 2) out float out_position;
layout(location = 3) out vec4 out_color;  // alpha 0: the colour mode's
layout(location = 4) flat out uint out_patch;
layout(location = 5) flat out uint out_fiber;

void main() {
  const uint per_segment = tubeTessPatchesPerSegment(pc.rings, pc.vertices);
  const uint si = patch_index / per_segment, local = patch_index % per_segment;
  const uint row = local / pc.vertices, k = local % pc.vertices;
  const TubeSegment s = SegmentsRef(pc.segments).segments[si];
  const TubeNode a = NodesRef(pc.nodes).nodes[s.node], b = NodesRef(pc.nodes).nodes[s.node + 1u];
  const TubeTessSegment g = tubeTessSegment(s, a, b);
  const float x = gl_TessCoord.x, y = gl_TessCoord.y;
  // Corners exactly as the control stage's (the last one around is the first).
  const float around = x <= 0.0   ? tubeTessAround(k, pc.vertices)
                       : x >= 1.0 ? tubeTessAround(k + 1u, pc.vertices)
                                  : (float(k) + x) / float(pc.vertices);
  vec3 p, normal;
  float u;
  if (row < pc.rings) {
    u = y <= 0.0 ? float(row) / float(pc.rings) : (y >= 1.0 ? float(row + 1u) / float(pc.rings)
                                                               : (float(row) + y) / float(pc.rings));
    vec3 radial;
    p = tubeTessBodyPoint(g, u, around, radial);
    const float du = 0.25 / float(pc.rings);
    vec3 unused;
    const vec3 along = tubeTessBodyPoint(g, min(u + du, 1.0), around, unused) -
                       tubeTessBodyPoint(g, max(u - du, 0.0), around, unused);
    const vec3 offset = p - tubeTessCenter(g, u);
    normal = dot(along, along) > 0.0 ? offset - dot(offset, along) / dot(along, along) * along : offset;
    if (!(dot(normal, normal) > 0.0)) normal = radial;
  } else {
    const bool start = row == pc.rings;
    u = start ? 0.0 : 1.0;
    p = tubeTessCapPoint(g, start ? -1.0 : 1.0, around, y, normal);
  }
  const CameraBlock cam = CameraRef(pc.camera).camera;
  gl_Position = cameraTransformPoint(cam.view_projection, p);
  const uint planes = uint(cam.cuts.x);
  for (uint c = 0u; c < kMaxFrameClipPlanes; ++c)
    gl_ClipDistance[c] = c < planes ? dot(cam.clip_world[c].xyz, p) + cam.clip_world[c].w : 1.0;
  out_normal = normal;
  out_tangent = s.chord > 0.0 ? tubeTessTangent(g, u) : vec3(0.0);
  out_position = mix(a.point, b.point, u);
  out_color = vec4(0.0);
  if (a.color >> 24 != 0u || b.color >> 24 != 0u) {
    // Hermite in the colour, slopes per mm times the chord (as the ray casters).
    const float u2 = u * u, u3 = u2 * u;
    const vec4 ca = unpackUnorm4x8(a.color), cb = unpackUnorm4x8(b.color);
    const vec4 sa = unpackSnorm4x8(a.color_slope) * kTubeColorSlopeMax;
    const vec4 sb = unpackSnorm4x8(b.color_slope) * kTubeColorSlopeMax;
    const vec4 col = (2.0 * u3 - 3.0 * u2 + 1.0) * ca + (u3 - 2.0 * u2 + u) * s.chord * sa +
                     (-2.0 * u3 + 3.0 * u2) * cb + (u3 - u2) * s.chord * sb;
    out_color = vec4(clamp(col.rgb, 0.0, 1.0), 1.0);
  }
  out_patch = patch_index;
  out_fiber = s.fiber;
}
