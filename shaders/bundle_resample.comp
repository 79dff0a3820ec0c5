// Bundling, resample (shared/bundling.h): one invocation per fiber places
// its samples at equal arc-length intervals len / (n - 1) along the
// polyline, the first and the last on its end points (n = the host's
// sample count, bundling/bundle_setup.h; a fiber of one sample keeps its
// first point). The points are a chunk's (shared/bundling.h).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kBundleGroupSize

#include "glsl/bundling.glsl"

layout(push_constant, std430) uniform Push { BundleFiberPush pc; };

void main() {
  const uint local = bundleInvocation();
  if (local >= pc.fiber_count) return;
  const uint fiber = pc.fiber_first + local;
  BundleFloatsRef points = BundleFloatsRef(pc.points);
  BundleVec4Ref samples = BundleVec4Ref(pc.samples);
  const uint p0 = BundleUintsRef(pc.point_offsets).values[fiber] - pc.point_base;  // in the chunk
  const uint p1 = BundleUintsRef(pc.point_offsets).values[fiber + 1u] - pc.point_base;
  const uint s0 = BundleUintsRef(pc.sample_offsets).values[fiber];
  const uint s1 = BundleUintsRef(pc.sample_offsets).values[fiber + 1u];
  if (s1 == s0 || p1 == p0) return;
  const uint n = s1 - s0;
  float len = 0.0;
  for (uint i = p0 + 1u; i < p1; ++i) len += distance(bundlePoint(points, i - 1u), bundlePoint(points, i));
  samples.values[s0] = vec4(bundlePoint(points, p0), 0.0);
  if (n == 1u) return;
  const float spacing = len / float(n - 1u);
  uint seg = p0;  // segment seg .. seg + 1
  float seg_start = 0.0;
  float seg_len = p1 - p0 > 1u ? distance(bundlePoint(points, p0), bundlePoint(points, p0 + 1u)) : 0.0;
  for (uint k = 1u; k + 1u < n; ++k) {
    const float target = spacing * float(k);
    while (seg + 2u < p1 && seg_start + seg_len < target) {
      seg_start += seg_len;
      ++seg;
      seg_len = distance(bundlePoint(points, seg), bundlePoint(points, seg + 1u));
    }
    const float t = seg_len > 0.0 ? clamp((target - seg_start) / seg_len, 0.0, 1.0) : 0.0;
    samples.values[s0 + k] = vec4(mix(bundlePoint(points, seg), bundlePoint(points, seg + 1u), t), 0.0);
  }
  samples.values[s1 - 1u] = vec4(bundlePoint(points, p1 - 1u), 0.0);
}
