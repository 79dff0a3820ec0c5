// Geometry-shader fiblet pipeline (paper section 4.5, table 2): one point
// per fiblet in, the fiblet's line strip out. One invocation decodes its
// fiblet front to back exactly as fiblet_raster_serial.comp does (W_1, then
// W_k = W_{k-1} L_k, point k the translation of W_k: the same composition
// order, so the same points), emitting each point as it is known, then the
// joining vertex (the next fiblet's first point) unless the fiblet ends its
// fiber: at most kFibletMaxPoints + 1 = 61 vertices, which the pass checks
// against the device's maxGeometryOutputVertices and
// maxGeometryTotalOutputComponents. A geometry shader is serial per
// primitive by construction; that serial decode and the output-size limit
// are what the paper measured it for.
//
// Flat outputs come from the provoking vertex, the first of each segment
// (Vulkan's default): vertex k carries segment k's values (its index k
// within the fiblet, as the compute payload; its packed tangent from the
// world-space points, as the compute rasters' tangent cache) and the
// fiber, fiber_base + fiblet_fiber[fiblet] as the compute resolve writes.
// The cuts' clip planes clip with gl_ClipDistance like the lines baseline;
// the fiber filter and frustum were the cull's (a dropped fiber's fiblets
// never reach this stage).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/tangent.glsl"

layout(points) in;
layout(line_strip, max_vertices = 61) out;  // kFibletMaxPoints + the joining vertex

layout(push_constant, std430) uniform Push { FibletDrawPush pc; };

layout(location = 0) in uint in_fiblet[];

out gl_PerVertex {
  vec4 gl_Position;
  float gl_ClipDistance[kMaxFrameClipPlanes];
};

layout(location = 0) flat out uint out_fiber;
layout(location = 1) flat out uint out_segment;
layout(location = 2) flat out uint out_tangent;

void emitPoint(CameraBlock cam, vec3 p, uint fiber, uint segment, uint tangent) {
  gl_Position = cameraTransformPoint(cam.view_projection, p);
  const uint planes = uint(cam.cuts.x);
  for (uint i = 0u; i < kMaxFrameClipPlanes; ++i)
    gl_ClipDistance[i] = i < planes ? dot(cam.clip_world[i].xyz, p) + cam.clip_world[i].w : 1.0;
  out_fiber = fiber;
  out_segment = segment;
  out_tangent = tangent;
  EmitVertex();
}

void main() {
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  const uint fiblet = in_fiblet[0];
  if (fiblet >= ds.fiblet_count) return;
  const uint n = ds.points_per_fiblet;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  const uint flags = fibletRecordByte(records, base, fibletFlagsByte(n));
  const uint count = fibletCount(flags);
  if (count < 1u || count > n) return;  // the uploader validated the records; never draw garbage
  const bool joins = (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count;
  const uint used = count - 1u;
  if (used == 0u && !joins) return;  // a lone point draws nothing, as in the compute rasters
  const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
  const vec3 p0 = fibletRecordPoint(w0, w1, w2, 0u);
  const vec3 p1 = fibletRecordPoint(w0, w1, w2, 1u);
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  DirectionsRef directions = DirectionsRef(ds.directions);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  const uint fiber = pc.fiber_base + UintsRef(ds.fiblet_fiber).values[fiblet];

  // Each vertex is emitted once the next point is known (its segment's
  // tangent needs both ends).
  vec3 a_world = fibletToWorld(ds, p0);
  FibletTransform s = fibletInitialTransform(p0, p1, v);
  for (uint k = 0u; k < used; ++k) {
    if (k > 0u) s = fibletNextTransform(s, directions, records, base, k);
    const vec3 b_world = fibletToWorld(ds, s.t);
    emitPoint(cam, a_world, fiber, k, packSegmentTangent(b_world - a_world));
    a_world = b_world;
  }
  if (joins) {
    const vec3 b_world = fibletToWorld(ds, fibletFirstPoint(records, base + ds.record_words));
    emitPoint(cam, a_world, fiber, used, packSegmentTangent(b_world - a_world));
    a_world = b_world;
  }
  // The strip's last vertex provokes no segment.
  emitPoint(cam, a_world, fiber, 0u, 0u);
  EndPrimitive();
}
