// The body of the decode + raster pass; shaders/fiblet_raster.comp (scan
// in shared memory, any subgroup size) and shaders/fiblet_raster_subgroup.comp
// (scan by subgroup shuffles where a fiblet's LANES are one subgroup)
// include it with FIBLET_SUBGROUP_SCAN 0 or 1. See fiblet_raster.comp.
#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/raster_segment.glsl"
#include "glsl/tangent.glsl"

layout(constant_id = 0) const uint LANES = 64;         // 8, 16, 32 or 64
layout(constant_id = 1) const uint GROUP_FIBLETS = 1;  // LANES * GROUP_FIBLETS <= 64
layout(local_size_x_id = 2) in;                        // LANES * GROUP_FIBLETS

layout(push_constant, std430) uniform Push { FibletRasterPush pc; };

#if !FIBLET_SUBGROUP_SCAN
shared FibletTransform partial[LANES * GROUP_FIBLETS];
#endif

const uint kSlots = 64u;     // transform slots per fiblet (>= kFibletMaxPoints)
const uint kMaxRun = 8u;     // kSlots / the smallest LANES

#if FIBLET_SUBGROUP_SCAN
FibletTransform shuffleUpTransform(FibletTransform t, uint delta) {
  FibletTransform r;
  r.c0 = subgroupShuffleUp(t.c0, delta);
  r.c1 = subgroupShuffleUp(t.c1, delta);
  r.c2 = subgroupShuffleUp(t.c2, delta);
  r.t = subgroupShuffleUp(t.t, delta);
  return r;
}
#endif

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
#if FIBLET_SUBGROUP_SCAN
  // gl_SubgroupSize / LANES fiblets per subgroup, each in a cluster of LANES
  // consecutive invocations; the scan's `lane >= offset` guard keeps every
  // cluster to itself (a shuffle from the cluster below is never used).
  const uint slot = gl_SubgroupID * (gl_SubgroupSize / LANES) + gl_SubgroupInvocationID / LANES;
  const uint lane = gl_SubgroupInvocationID % LANES;
#else
  const uint slot = gl_LocalInvocationID.x / LANES;  // which fiblet of the workgroup
  const uint lane = gl_LocalInvocationID.x % LANES;
#endif
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
  //    The loops run over the constant `run` (LANES is a specialization
  //    constant) with a guard instead of up to the data-dependent `end`, so
  //    the compiler can unroll them and keep local[] in registers: indexed
  //    by a loop counter of unknown range it went to (slower) local memory.
  vec3 local[kMaxRun];
  FibletTransform s = identityTransform();
  for (uint j = 0u; j < run; ++j) {
    const uint k = first + j;
    if (k < end) {
      const FibletTransform t = k == 0u ? fibletInitialTransform(p0, p1, v)
                                        : fibletTableTransform(directions, fibletRecordByte(records, base, fibletCodeByte(k + 1u)));
      s = j == 0u ? t : fibletCompose(s, t);
      local[j] = s.t;
    }
  }
#if FIBLET_SUBGROUP_SCAN
  // 2. Inclusive scan of the runs across the subgroup (shuffles, no shared
  //    memory, no barriers), then the exclusive prefix from the lane below.
  for (uint offset = 1u; offset < LANES; offset *= 2u) {
    const FibletTransform below = shuffleUpTransform(s, offset);
    if (lane >= offset) s = fibletCompose(below, s);
  }
  const FibletTransform below = shuffleUpTransform(s, 1u);
  const FibletTransform e = lane == 0u ? identityTransform() : below;
#else
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
#endif
#if !FIBLET_SUBGROUP_SCAN
  const FibletTransform e = lane == 0u ? identityTransform() : partial[me - 1u];
#endif
  if (!valid) return;

  // 3. Points of the run through the exclusive prefix, and their segments.
  const CameraBlock cam = CameraRef(pc.camera).camera;
  VisibilityRef vis = VisibilityRef(pc.visibility);
  // Each point is projected once (clip space), each segment uses two.
  vec3 a_world = fibletToWorld(ds, lane == 0u ? p0 : e.t);  // point `first`
  vec4 a = cameraTransformPoint(cam.view_projection, a_world);
  const bool cache = pc.tangents != 0ul;
  UintsOutRef tangents = UintsOutRef(pc.tangents);
  // Scene-global fiblet (shared/scene_table.h) for the keys and the cache.
  const uint global = pc.fiblet_base + fiblet;
  for (uint j = 0u; j < run; ++j) {
    const uint k = first + j;
    if (k < end) {
      const vec3 b_world = fibletToWorld(ds, fibletRotate(e, local[j]) + e.t);  // point k + 1
      const vec4 b = cameraTransformPoint(cam.view_projection, b_world);
      rasterClipSegment(vis, cam, a, b, (uint64_t(global) << kKeySegmentBits) | uint64_t(k));
      if (cache) tangents.values[global * kSlots + k] = packSegmentTangent(b_world - a_world);
      a = b;
      a_world = b_world;
    }
  }
  // The joining segment, drawn by the lane that owns the last point (point
  // `used`: lane 0 when the fiblet has one point).
  const bool owns_last = used == 0u ? lane == 0u : (used - 1u >= first && used - 1u < first + run);
  if (owns_last && (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count) {
    const vec3 b = fibletToWorld(ds, fibletFirstPoint(records, base + ds.record_words));
    rasterClipSegment(vis, cam, a, cameraTransformPoint(cam.view_projection, b),
                      (uint64_t(global) << kKeySegmentBits) | uint64_t(used));
    if (cache) tangents.values[global * kSlots + used] = packSegmentTangent(b - a_world);
  }
}
