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
// KNOWN PROBLEM: on lavapipe (Mesa) the isolines come out with segments
// joining points of different fiblets, and a frame is 50x slower than the
// geometry pipeline's; the decode in the control stage (a 32-lane scan, or
// two 31-point halves) and a patch output for the fiblet gave the same
// wrong image, so the cause is not the decode's placement; nor are the clip
// distances (the same image without them) or the levels varying from patch
// to patch (the same with every patch at level 60). Not resolved (a GPU
// driver would tell whether lavapipe is at fault):
// tests/unit/gpu_fiblet_graphics_test.cpp keeps this pipeline's image
// tests DISABLED_.
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


out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[kMaxFrameClipPlanes];
};

layout(location = 0) flat out uint out_fiber;
layout(location = 1) flat out uint out_segment;
layout(location = 2) flat out uint out_tangent;

void main() {
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  // The patch is the draw's vertex gl_PrimitiveID: the fiblet as the vertex
  // shader found it, found again here rather than passed as a patch output
  // (a patch output gave the same wrong image on lavapipe: see the tests).
  const uint slot = uint(gl_PrimitiveID);
  const uint fiblet = pc.list != 0ul ? FibletListRef(pc.list).fiblets[slot] : slot;
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
  // (Only when the segment is drawn: the last fiblet has no next record.)
  if (i + 1u > used && i < segments) b = fibletFirstPoint(records, base + ds.record_words);
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
