// Tessellation fiblet pipeline, evaluation stage: vertex i of the fiblet's
// isoline (i = gl_TessCoord.x * segments, exact for these small integers)
// is point i of the fiblet, decoded here from the fiblet's start: W_1, then
// W_k = W_{k-1} L_k up to point i + 1 (its segment's tangent needs both
// ends), the order of every serial decoder, so the points are the compute
// pipeline's bit for bit. That is O(n^2) compositions per fiblet (about 30
// per vertex for 60-point fiblets, against one in the geometry shader's
// serial walk): the cost the paper's tessellation variant pays for
// spreading a fiblet over independent vertex invocations, and here the
// price of a decode that is right on every driver (fiblet_lines.tesc says
// why the control stage does not decode).
//
// The fiblet comes from the control stage as a patch output (the vertex
// shader read it at gl_VertexIndex), not from gl_PrimitiveID: the draws may
// be split (fiblet_graphics_pass.h: lavapipe mixes up patches in large
// draws), and gl_PrimitiveID restarts at every draw.
//
// Flat outputs as fiblet_lines.geom's: vertex i carries segment i's values
// (its index within the fiblet, as the compute payload; the packed tangent
// of point i -> i + 1 from world-space points; the fiber as the compute
// resolve writes it) for the first-vertex provoking convention, on the
// assumption that the tessellator emits each isoline segment from its
// lower u to its higher (the tests compare the segment ids with the compute
// pipeline's, which would catch the other order). Clip planes as the lines
// baseline.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/tangent.glsl"

layout(isolines, equal_spacing) in;

layout(push_constant, std430) uniform Push { FibletDrawPush pc; };

layout(location = 0) patch in uint patch_fiblet;


out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[kMaxFrameClipPlanes];
};

layout(location = 0) flat out uint out_fiber;
layout(location = 1) flat out uint out_segment;
layout(location = 2) flat out uint out_tangent;

void main() {
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  const uint fiblet = patch_fiblet;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  const uint flags = fibletRecordByte(records, base, fibletFlagsByte(ds.points_per_fiblet));
  const uint count = fibletCount(flags);
  const uint used = count - 1u;  // decoded segments; segment `used` (when drawn) is the joining one
  // (The control stage drew the patch: count is valid.)
  const uint segments = used + ((flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count ? 1u : 0u);
  const uint i = min(uint(round(gl_TessCoord.x * float(segments))), segments);
  const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
  const vec3 p0 = fibletRecordPoint(w0, w1, w2, 0u);
  DirectionsRef directions = DirectionsRef(ds.directions);
  // a = point i, b = point i + 1 (the joining point past the last).
  vec3 a = p0, b = p0;
  const uint need = min(i + 1u, used);  // decoded points needed beyond p0
  if (need >= 1u) {
    FibletTransform s = fibletInitialTransform(p0, fibletRecordPoint(w0, w1, w2, 1u), vec3(ds.v_x, ds.v_y, ds.v_z));
    for (uint k = 1u; k < need; ++k) {
      if (k == i) a = s.t;
      s = fibletNextTransform(s, directions, records, base, k);
    }
    if (i >= 1u && i == need) a = s.t;  // i = used: point i is the last decoded one
    b = s.t;
  }
  // Past the decoded points lies the next fiblet's first point: b of the
  // joining segment (i = used), and a of the isoline's last vertex when the
  // fiblet has that segment (i = used + 1). Only then: the last fiblet has
  // no next record.
  if (segments > used && i + 1u > used) {
    const vec3 next = fibletFirstPoint(records, base + ds.record_words);
    if (i == used) b = next;
    else a = next;
  }
  const vec3 p = fibletToWorld(ds, a);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  gl_Position = cameraTransformPoint(cam.view_projection, p);
  const uint planes = uint(cam.cuts.x);
  for (uint c = 0u; c < kMaxFrameClipPlanes; ++c)
    gl_ClipDistance[c] = c < planes ? dot(cam.clip_world[c].xyz, p) + cam.clip_world[c].w : 1.0;
  out_fiber = pc.fiber_base + UintsRef(ds.fiblet_fiber).values[fiblet];
  // The last vertex provokes no segment.
  out_segment = i < segments ? i : 0u;
  out_tangent = i < segments ? packSegmentTangent(fibletToWorld(ds, b) - p) : 0u;
}
