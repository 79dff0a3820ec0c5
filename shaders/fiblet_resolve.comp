// Resolve for the compute pipeline (DESIGN.md section 6, step 3): per pixel,
// the winning key's payload (scene-global fiblet, segment) becomes a G-buffer
// texel: the fiblet's dataset from the scene table (shared/scene_table.h),
// the scene-global fiber from the dataset's per-fiblet fiber table plus its
// fiber base, the tangent from the rasters'
// tangent cache when there is one, else by decoding the fiblet from its
// start up to the segment (sequential composition, at most 60 steps; only
// covered pixels pay for it). Which of the two is a specialisation constant,
// not a branch on the push constant: a CPU device's SIMD lanes run both
// sides of every branch, and the decode would cost every pixel.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/render_push.h"
#include "shared/scene_table.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize
// True: pc.tangents is the rasters' tangent cache; false: decode.
layout(constant_id = 0) const bool kTangentCache = true;

layout(push_constant, std430) uniform Push { FibletResolvePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer SceneTableRef {
  SceneTableHeader header;
  SceneDataset datasets[];
};

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const uint64_t key = VisibilityRef(pc.visibility).keys[visibilityIndex(p.x, p.y, pc.width)];
  GBufferTexel texel;
  texel.depth = 1.0;
  texel.fiber = kNoFiberId;
  texel.segment = 0u;
  texel.tangent = 0u;
  if (key != 0xFFFFFFFFFFFFFFFFul) {
    const uint64_t payload = visibilityPayload(key);
    const uint global = uint(payload >> kKeySegmentBits);
    const uint segment = uint(payload) & ((1u << kKeySegmentBits) - 1u);
    // The last dataset whose first fiblet is at or before `global` (bases
    // increase; a handful of entries, and neighbouring pixels take the same
    // branch, so a scan beats a binary search's divergence).
    SceneTableRef scene = SceneTableRef(pc.scene);
    uint entry = 0u;
    for (uint i = 1u; i < scene.header.count; ++i)
      if (scene.datasets[i].fiblet_base <= global) entry = i;
    const SceneDataset owner = scene.datasets[entry];
    const FibletDataset ds = DatasetRef(owner.block).ds;
    const uint fiblet = global - owner.fiblet_base;
    if (kTangentCache) {
      // The rasters left every drawn segment's tangent in the cache
      // (indexed by the global fiblet).
      texel.tangent = UintsRef(pc.tangents).values[global * 64u + segment];
    } else {
      WordsRef records = WordsRef(ds.records);
      const uint base = fiblet * ds.record_words;
      const uint n = ds.points_per_fiblet;
      const uint count = fibletCount(fibletRecordByte(records, base, fibletFlagsByte(n)));
      const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
      const vec3 p0 = fibletRecordPoint(w0, w1, w2, 0u);
      const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
      vec3 a = p0, b = p0;
      if (count >= 2u) {
        // W_1, then W_k = W_{k-1} L_k: after k steps the translation is point k.
        FibletTransform w = fibletInitialTransform(p0, fibletRecordPoint(w0, w1, w2, 1u), v);
        const uint last = min(segment + 1u, count - 1u);
        for (uint k = 2u; k <= last; ++k) {
          a = w.t;
          w = fibletNextTransform(w, DirectionsRef(ds.directions), records, base, k - 1u);
        }
        if (segment + 1u < count) {
          if (segment == 0u) a = p0;
          b = w.t;
        } else {
          a = w.t;  // the joining segment: last point -> next fiblet's first point
        }
      }
      if (segment + 1u >= count) b = fibletFirstPoint(records, base + ds.record_words);
      // Normalised -> world is a uniform scale plus a translation: the unit
      // tangent is the same in both spaces.
      texel.tangent = packSegmentTangent(b - a);
    }
    texel.depth = visibilityDepth(key);
    texel.fiber = owner.fiber_base + UintsRef(ds.fiblet_fiber).values[fiblet];
    texel.segment = segment;
  }
  GBufferRef(pc.gbuffer).texels[index] = texel;
}
