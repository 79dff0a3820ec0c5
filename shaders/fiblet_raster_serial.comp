// Decode + raster for CPU devices (lavapipe): one invocation decodes one
// fiblet front to back and rasterises each segment as soon as its end point
// is known. The paper's parallel prefix (fiblet_raster.comp) spreads a
// fiblet over many invocations because a GPU has threads to spare; a CPU
// runs a workgroup's invocations as 8-wide SIMD in a loop, so the scan's
// extra compositions, shuffles and per-run point arrays are pure overhead
// there. Serially each point costs one composition (W_1 L_2 ... L_k, the
// order the lane that owns the fiblet's first run uses in the scan variants,
// so the points match theirs to float rounding), and nothing is kept but the
// running transform and the previous projected point.
// GROUP_FIBLETS fiblets (invocations) per workgroup: a lavapipe workgroup
// costs about a microsecond to launch.
// Payload and joining segment as fiblet_raster.comp.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/raster_segment.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x_id = 0) in;  // GROUP_FIBLETS

layout(push_constant, std430) uniform Push { FibletRasterPush pc; };

void main() {
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  const uint group_index = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint flat_index = group_index * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  uint fiblet = flat_index;
  if (pc.list != 0ul) {
    FibletListRef list = FibletListRef(pc.list);
    if (flat_index >= list.header.count) return;
    fiblet = list.fiblets[flat_index];
  }
  if (fiblet >= ds.fiblet_count) return;
  const uint n = ds.points_per_fiblet;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  const uint flags = fibletRecordByte(records, base, fibletFlagsByte(n));
  const uint count = fibletCount(flags);
  if (count < 1u || count > n) return;  // the uploader validated the records; never draw garbage
  const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
  const vec3 p0 = fibletRecordPoint(w0, w1, w2, 0u);
  const vec3 p1 = fibletRecordPoint(w0, w1, w2, 1u);
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  DirectionsRef directions = DirectionsRef(ds.directions);

  const CameraBlock cam = CameraRef(pc.camera).camera;
  VisibilityRef vis = VisibilityRef(pc.visibility);
  const bool cache = pc.tangents != 0ul;
  UintsOutRef tangents = UintsOutRef(pc.tangents);
  // Scene-global fiblet (shared/scene_table.h) for the key and the cache.
  const uint global = pc.fiblet_base + fiblet;
  const uint64_t fiblet_key = uint64_t(global) << kKeySegmentBits;
  vec3 a_world = fibletToWorld(ds, p0);
  vec4 a = cameraTransformPoint(cam.view_projection, a_world);
  // Transform k gives point k + 1: W_1 for k = 0, then L_{k+1}.
  const uint used = count - 1u;
  FibletTransform s = fibletInitialTransform(p0, p1, v);
  for (uint k = 0u; k < used; ++k) {
    if (k > 0u) s = fibletNextTransform(s, directions, records, base, k);
    const vec3 b_world = fibletToWorld(ds, s.t);
    const vec4 b = cameraTransformPoint(cam.view_projection, b_world);
    rasterClipSegment(vis, cam, a, b, fiblet_key | uint64_t(k));
    if (cache) tangents.values[global * 64u + k] = packSegmentTangent(b_world - a_world);
    a = b;
    a_world = b_world;
  }
  if ((flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count) {
    const vec3 b = fibletToWorld(ds, fibletFirstPoint(records, base + ds.record_words));
    rasterClipSegment(vis, cam, a, cameraTransformPoint(cam.view_projection, b), fiblet_key | uint64_t(used));
    if (cache) tangents.values[global * 64u + used] = packSegmentTangent(b - a_world);
  }
}
