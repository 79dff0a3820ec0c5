// Decode + raster (DESIGN.md section 6, step 2; fiblets paper 3.3.2).
// LANES invocations decode one fiblet (a specialization constant: 64, 32,
// 16 or 8, from the device's subgroup size so a fiblet fills whole
// subgroups); a workgroup holds GROUP_FIBLETS fiblets (1 on GPUs: one
// workgroup per fiblet as in the paper; 64 / LANES on CPU devices such as
// lavapipe, where every workgroup costs about a microsecond of dispatch).
// The fiblet's up to 64 point transforms are split into LANES runs of
// 64 / LANES consecutive transforms:
//   1. each invocation composes its run sequentially, keeping the run's
//      local prefix translations (at most 8 for LANES = 8);
//   2. a log-step inclusive scan of the runs' products in shared memory
//      (Hillis-Steele: log2(LANES) steps, shared memory + barriers, so it
//      works for any subgroup size);
//   3. each invocation maps its local points through the exclusive prefix
//      (a rotation and a translation each) and rasterises the segment that
//      starts at each point (glsl/raster_segment.glsl: the CPU reference's
//      pixel rule).
// With LANES = 64 this is the paper's one-transform-per-thread scan; fewer
// lanes do less work (about one composition per point instead of
// log2(64) = 6) and fewer barriers, which a CPU rasteriser needs.
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
#include "glsl/tangent.glsl"

layout(constant_id = 0) const uint LANES = 64;         // 8, 16, 32 or 64
layout(constant_id = 1) const uint GROUP_FIBLETS = 1;  // LANES * GROUP_FIBLETS <= 64
layout(local_size_x_id = 2) in;                        // LANES * GROUP_FIBLETS

layout(push_constant, std430) uniform Push { FibletRasterPush pc; };

shared FibletTransform partial[LANES * GROUP_FIBLETS];

const uint kSlots = 64u;     // transform slots per fiblet (>= kFibletMaxPoints)
const uint kMaxRun = 8u;     // kSlots / the smallest LANES

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
  const uint slot = gl_LocalInvocationID.x / LANES;  // which fiblet of the workgroup
  const uint lane = gl_LocalInvocationID.x % LANES;
  const uint group_index = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint flat_index = group_index * GROUP_FIBLETS + slot;
  // No early return before the barriers: a workgroup may hold valid and
  // invalid fiblets; invalid ones run the scan on identities.
  bool valid = true;
  uint fiblet = flat_index;
  if (pc.list != 0ul) {
    FibletListRef list = FibletListRef(pc.list);
    valid = flat_index < list.header.count;
    fiblet = valid ? list.fiblets[flat_index] : 0u;
  }
  valid = valid && fiblet < ds.fiblet_count;
  const uint n = ds.points_per_fiblet;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  uint flags = 0u, count = 0u;
  if (valid) {
    flags = fibletRecordByte(records, base, fibletFlagsByte(n));
    count = fibletCount(flags);
    valid = count >= 1u && count <= n;  // the uploader validated the records; never draw garbage
  }
  vec3 p0 = vec3(0.0), p1 = vec3(0.0);
  if (valid) {
    const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
    p0 = fibletRecordPoint(w0, w1, w2, 0u);
    p1 = fibletRecordPoint(w0, w1, w2, 1u);
  }
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  DirectionsRef directions = DirectionsRef(ds.directions);
  // Transform k (k < used) gives point k + 1: W_1 for k = 0, L_{k+1} after.
  const uint used = valid ? count - 1u : 0u;
  const uint run = kSlots / LANES;
  const uint first = lane * run;
  const uint end = min(first + run, used);

  // 1. The run's product, and its local prefix translations: local[j] is
  //    the point first + j + 1 in the frame of the run's start.
  vec3 local[kMaxRun];
  FibletTransform s = identityTransform();
  for (uint k = first; k < end; ++k) {
    const FibletTransform t = k == 0u ? fibletInitialTransform(p0, p1, v)
                                      : fibletTableTransform(directions, fibletRecordByte(records, base, fibletCodeByte(k + 1u)));
    s = k == first ? t : fibletCompose(s, t);
    local[k - first] = s.t;
  }
  const uint me = slot * LANES + lane;
  partial[me] = s;
  barrier();
  // 2. Inclusive scan of the runs within the fiblet: lane i ends with runs 0..i.
  for (uint offset = 1u; offset < LANES; offset *= 2u) {
    FibletTransform combined;
    const bool combines = lane >= offset;
    if (combines) combined = fibletCompose(partial[me - offset], partial[me]);
    barrier();
    if (combines) partial[me] = combined;
    barrier();
  }
  if (!valid) return;

  // 3. Points of the run through the exclusive prefix, and their segments.
  const CameraBlock cam = CameraRef(pc.camera).camera;
  VisibilityRef vis = VisibilityRef(pc.visibility);
  const FibletTransform e = lane == 0u ? identityTransform() : partial[me - 1u];
  // Each point is projected once (clip space), each segment uses two.
  vec3 a_world = fibletToWorld(ds, lane == 0u ? p0 : e.t);  // point `first`
  vec4 a = cameraTransformPoint(cam.view_projection, a_world);
  const bool cache = pc.tangents != 0ul;
  UintsOutRef tangents = UintsOutRef(pc.tangents);
  for (uint k = first; k < end; ++k) {
    const vec3 b_world = fibletToWorld(ds, fibletRotate(e, local[k - first]) + e.t);  // point k + 1
    const vec4 b = cameraTransformPoint(cam.view_projection, b_world);
    rasterClipSegment(vis, cam, a, b, (uint64_t(fiblet) << kKeySegmentBits) | uint64_t(k));
    if (cache) tangents.values[fiblet * kSlots + k] = packSegmentTangent(b_world - a_world);
    a = b;
    a_world = b_world;
  }
  // The joining segment, drawn by the lane that owns the last point (point
  // `used`: lane 0 when the fiblet has one point).
  const bool owns_last = used == 0u ? lane == 0u : (used - 1u >= first && used - 1u < first + run);
  if (owns_last && (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count) {
    const vec3 b = fibletToWorld(ds, fibletFirstPoint(records, base + ds.record_words));
    rasterClipSegment(vis, cam, a, cameraTransformPoint(cam.view_projection, b),
                      (uint64_t(fiblet) << kKeySegmentBits) | uint64_t(used));
    if (cache) tangents.values[fiblet * kSlots + used] = packSegmentTangent(b - a_world);
  }
}
