// Decode + raster (DESIGN.md section 6, step 2; fiblets paper 3.3.2): one
// workgroup per fiblet. Each invocation builds the local transform of one
// point, a log-step inclusive scan in shared memory composes them (shared
// memory and barriers, so any subgroup size works: 8 on lavapipe, 32 or 64
// on GPUs), and invocation i then rasterises segment i (points i -> i + 1)
// into the visibility buffer; the last point's invocation draws the segment
// that joins the next fiblet of the same fiber (its first point).
// Payload: fiblet << 6 | i (shared/render_config.h).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/raster_segment.glsl"

layout(local_size_x = 64) in;  // kRasterGroupSize

layout(push_constant, std430) uniform Push { FibletRasterPush pc; };

shared FibletTransform lanes[64];

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
  const uint used = count - 1u;  // transforms W_1 .. W_{count-1}
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  if (used > 0u) {
    if (lane == 0u) {
      lanes[0] = fibletInitialTransform(p0, fibletRecordPoint(w0, w1, w2, 1u), v);
    } else if (lane < used) {
      const uint code = fibletRecordByte(records, base, fibletCodeByte(lane + 1u));
      const vec4 d = DirectionsRef(ds.directions).directions[code];
      lanes[lane] = fibletLocalTransform(d.xyz, v, ds.delta);
    }
  }
  barrier();
  // Hillis-Steele scan: after it lane i holds W_{i+1}, whose translation is
  // point i + 1.
  for (uint offset = 1u; offset < used; offset *= 2u) {
    FibletTransform combined;
    const bool combines = lane >= offset && lane < used;
    if (combines) combined = fibletCompose(lanes[lane - offset], lanes[lane]);
    barrier();
    if (combines) lanes[lane] = combined;
    barrier();
  }

  const CameraBlock cam = CameraRef(pc.camera).camera;
  VisibilityRef vis = VisibilityRef(pc.visibility);
  const uint64_t payload = (uint64_t(fiblet) << kKeySegmentBits) | uint64_t(lane);
  if (lane < used) {
    // Segment lane: point lane -> point lane + 1.
    const vec3 a = lane == 0u ? p0 : lanes[lane - 1u].t;
    rasterSegment(vis, cam, fibletToWorld(ds, a), fibletToWorld(ds, lanes[lane].t), payload);
  } else if (lane == used && (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count) {
    // The joining segment: last point -> the next fiblet's first point.
    const vec3 a = used == 0u ? p0 : lanes[used - 1u].t;
    const vec3 b = fibletFirstPoint(records, base + ds.record_words);
    rasterSegment(vis, cam, fibletToWorld(ds, a), fibletToWorld(ds, b), payload);
  }
}
