// Decodes every fiblet of an uploaded dataset (render/gpu/dataset.h) to
// normalised points, reading the records, the direction table, N, delta and
// V only through the FibletDataset block: the GPU test checks that what the
// uploader wrote is what a pass needs, bit for bit against the CPU scan.
// The decode itself is fiblet_decode_test.comp's: one workgroup of 64 per
// fiblet, the log-step inclusive scan of shared/fiblet.h in shared memory.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/fiblet.h"
#include "shared/fiblet_dataset.h"
#include "shared/dataset_decode_push.h"

// 64 >= kFibletMaxPoints: one invocation per point, the rest idle.
layout(local_size_x = 64) in;

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer DatasetBlock { FibletDataset ds; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Words { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer DirectionTable { vec4 directions[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer Points { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer Counts { uint values[]; };

layout(push_constant, std430) uniform Push { DatasetDecodePush pc; };

// Lane i's transform; the scan reads neighbours across invocations.
shared FibletTransform lanes[64];

uint recordByte(Words records, uint base, uint byte_index) {
  return fibletByteOfWord(records.words[base + byte_index / 4u], byte_index);
}

vec3 recordPoint(uint w0, uint w1, uint w2, uint which) {
  return vec3(fibletDequantize(fibletCoordOfWords(w0, w1, w2, 3u * which)),
              fibletDequantize(fibletCoordOfWords(w0, w1, w2, 3u * which + 1u)),
              fibletDequantize(fibletCoordOfWords(w0, w1, w2, 3u * which + 2u)));
}

void storePoint(Points points, uint base, uint k, vec3 p) {
  points.values[base + 3u * k] = p.x;
  points.values[base + 3u * k + 1u] = p.y;
  points.values[base + 3u * k + 2u] = p.z;
}

void main() {
  const FibletDataset ds = DatasetBlock(pc.dataset).ds;
  // The fiblet is uniform across the workgroup, so the early returns and
  // the barriers below stay in uniform control flow.
  const uint fiblet = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (fiblet >= ds.fiblet_count) return;
  const uint n = ds.points_per_fiblet;
  const uint lane = gl_LocalInvocationID.x;
  Words records = Words(ds.records);
  Points points = Points(pc.points);
  const uint base = fiblet * ds.record_words;
  const uint out_base = fiblet * 3u * n;

  const uint count = fibletCount(recordByte(records, base, fibletFlagsByte(n)));
  if (lane == 0u) Counts(pc.counts).values[fiblet] = (count >= 1u && count <= n) ? count : 0u;
  if (count < 1u || count > n) return;

  const uint w0 = records.words[base];
  const uint w1 = records.words[base + 1u];
  const uint w2 = records.words[base + 2u];
  const vec3 p0 = recordPoint(w0, w1, w2, 0u);
  if (lane == 0u) storePoint(points, out_base, 0u, p0);
  if (count == 1u) return;

  // Lane i holds W_1 (i = 0) or L_{i+1}, for the points 1..count-1.
  const uint used = count - 1u;
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  if (lane == 0u) {
    lanes[0] = fibletInitialTransform(p0, recordPoint(w0, w1, w2, 1u), v);
  } else if (lane < used) {
    const uint code = recordByte(records, base, fibletCodeByte(lane + 1u));
    const vec4 d = DirectionTable(ds.directions).directions[code];
    lanes[lane] = fibletLocalTransform(d.xyz, v, ds.delta);
  }
  barrier();

  // Hillis-Steele inclusive scan: at offset o, lane i >= o becomes
  // lanes[i - o] * lanes[i], all reads of a step before any write.
  for (uint offset = 1u; offset < used; offset *= 2u) {
    FibletTransform combined;
    const bool combines = lane >= offset && lane < used;
    if (combines) combined = fibletCompose(lanes[lane - offset], lanes[lane]);
    barrier();
    if (combines) lanes[lane] = combined;
    barrier();
  }

  // Lane i now holds W_{i+1}: point i+1 is its translation.
  if (lane < used) storePoint(points, out_base, lane + 1u, lanes[lane].t);
}
