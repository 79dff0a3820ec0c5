// Decode + raster (DESIGN.md section 6, step 2; fiblets paper 3.3.2): one
// workgroup per fiblet, LANES invocations (a specialization constant: 64,
// 32 or 8, chosen from the device's subgroup size so a fiblet fills whole
// subgroups). The fiblet's up to 64 point transforms are split into LANES
// runs of 64 / LANES consecutive transforms:
//   1. each invocation composes its run sequentially (its partial product);
//   2. a log-step inclusive scan of the partial products in shared memory
//      (Hillis-Steele: log2(LANES) steps, shared memory + barriers, so it
//      works for any subgroup size);
//   3. each invocation re-composes its run from the exclusive prefix,
//      getting its points, and rasterises the segment that starts at each
//      of them (glsl/raster_segment.glsl, the CPU reference's pixel rule).
// With LANES = 64 this is the paper's one-transform-per-thread scan; fewer
// lanes do less work (about 2 compositions per point instead of log2 64 = 6)
// and fewer barriers, which is what a CPU rasteriser (lavapipe) needs.
// The invocation that owns the last point also draws the segment that
// joins the next fiblet of the same fiber (its first point).
// Payload: fiblet << 6 | index of the segment's first point in the fiblet.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/raster_segment.glsl"

layout(constant_id = 0) const uint LANES = 64;  // 8, 16, 32 or 64
layout(local_size_x_id = 0) in;

layout(push_constant, std430) uniform Push { FibletRasterPush pc; };

shared FibletTransform partial[LANES];

const uint kSlots = 64u;  // transform slots per fiblet (>= kFibletMaxPoints)

FibletTransform identityTransform() {
  FibletTransform r;
  r.c0 = vec3(1.0, 0.0, 0.0);
  r.c1 = vec3(0.0, 1.0, 0.0);
  r.c2 = vec3(0.0, 0.0, 1.0);
  r.t = vec3(0.0);
  return r;
}

void main() {
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  // Uniform across the workgroup: the returns below keep barriers in
  // uniform control flow.
  const uint flat_index = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  uint fiblet = flat_index;
  if (pc.list != 0ul) {
    FibletListRef list = FibletListRef(pc.list);
    if (flat_index >= list.header.count) return;
    fiblet = list.fiblets[flat_index];
  }
  if (fiblet >= ds.fiblet_count) return;
  const uint n = ds.points_per_fiblet;
  const uint lane = gl_LocalInvocationID.x;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  const uint flags = fibletRecordByte(records, base, fibletFlagsByte(n));
  const uint count = fibletCount(flags);
  if (count < 1u || count > n) return;  // the uploader validated the records; never draw garbage

  const uint w0 = records.words[base];
  const uint w1 = records.words[base + 1u];
  const uint w2 = records.words[base + 2u];
  const vec3 p0 = fibletRecordPoint(w0, w1, w2, 0u);
  const vec3 p1 = fibletRecordPoint(w0, w1, w2, 1u);
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  DirectionsRef directions = DirectionsRef(ds.directions);
  // Transform k (k < used) gives point k + 1: W_1 for k = 0, L_{k+1} after.
  const uint used = count - 1u;
  const uint run = kSlots / LANES;
  const uint first = lane * run;
  const uint end = min(first + run, used);

  // 1. This run's partial product.
  FibletTransform s = identityTransform();
  for (uint k = first; k < end; ++k) {
    FibletTransform t;
    if (k == 0u) {
      t = fibletInitialTransform(p0, p1, v);
    } else {
      t = fibletTableTransform(directions, fibletRecordByte(records, base, fibletCodeByte(k + 1u)));
    }
    s = k == first ? t : fibletCompose(s, t);
  }
  partial[lane] = s;
  barrier();
  // 2. Inclusive scan of the partial products: lane i ends with runs 0..i.
  for (uint offset = 1u; offset < LANES; offset *= 2u) {
    FibletTransform combined;
    const bool combines = lane >= offset;
    if (combines) combined = fibletCompose(partial[lane - offset], partial[lane]);
    barrier();
    if (combines) partial[lane] = combined;
    barrier();
  }

  // 3. Points of the run from the exclusive prefix, and their segments.
  const CameraBlock cam = CameraRef(pc.camera).camera;
  VisibilityRef vis = VisibilityRef(pc.visibility);
  FibletTransform w = lane == 0u ? identityTransform() : partial[lane - 1u];
  vec3 a = fibletToWorld(ds, lane == 0u ? p0 : w.t);  // point `first`
  for (uint k = first; k < end; ++k) {
    if (k == 0u) {
      w = fibletInitialTransform(p0, p1, v);
    } else {
      w = fibletCompose(w, fibletTableTransform(directions, fibletRecordByte(records, base, fibletCodeByte(k + 1u))));
    }
    const vec3 b = fibletToWorld(ds, w.t);  // point k + 1
    rasterSegment(vis, cam, a, b, (uint64_t(fiblet) << kKeySegmentBits) | uint64_t(k));
    a = b;
  }
  // The joining segment, drawn by the lane that owns the last point (point
  // `used`: lane 0 when the fiblet has one point).
  const bool owns_last = used == 0u ? lane == 0u : (used - 1u >= first && used - 1u < first + run);
  if (owns_last && (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count) {
    const vec3 b = fibletToWorld(ds, fibletFirstPoint(records, base + ds.record_words));
    rasterSegment(vis, cam, a, b, (uint64_t(fiblet) << kKeySegmentBits) | uint64_t(used));
  }
}
