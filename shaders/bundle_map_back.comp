// Bundling, map back (shared/bundling.h): one invocation per fiber moves
// each original point by the displacement of its samples (bundled minus
// unbundled) interpolated linearly at the point's arc length, in sample
// units c / spacing, so a fiber keeps its points, their count and order,
// and the detail between samples. A fiber of one sample moves rigidly.
// In place (moved = points) on a chunk of fibers (shared/bundling.h): each
// invocation reads its fiber's points before it overwrites them, keeping
// the unmoved previous point for the arc length.
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
  BundleFloatsRef output_points = BundleFloatsRef(pc.moved);
  BundleVec4Ref bundled = BundleVec4Ref(pc.samples);
  BundleVec4Ref originals = BundleVec4Ref(pc.originals);
  const uint p0 = BundleUintsRef(pc.point_offsets).values[fiber] - pc.point_base;  // in the chunk
  const uint p1 = BundleUintsRef(pc.point_offsets).values[fiber + 1u] - pc.point_base;
  const uint s0 = BundleUintsRef(pc.sample_offsets).values[fiber];
  const uint s1 = BundleUintsRef(pc.sample_offsets).values[fiber + 1u];
  if (p1 == p0) return;
  const uint n = s1 - s0;
  float len = 0.0;
  for (uint i = p0 + 1u; i < p1; ++i) len += distance(bundlePoint(points, i - 1u), bundlePoint(points, i));
  const float spacing = n > 1u ? len / float(n - 1u) : 0.0;
  float arc = 0.0;
  vec3 previous = bundlePoint(points, p0);  // unmoved: `moved` may be `points`
  for (uint i = p0; i < p1; ++i) {
    const vec3 p = bundlePoint(points, i);
    if (i > p0) arc += distance(previous, p);
    previous = p;
    vec3 shift = vec3(0.0);
    if (n == 1u || spacing <= 0.0) {
      shift = bundled.values[s0].xyz - originals.values[s0].xyz;
    } else {
      // The last point is the last sample's, whatever the rounding of its arc.
      const float u = i + 1u == p1 ? float(n - 1u) : clamp(arc / spacing, 0.0, float(n - 1u));
      const uint k = min(uint(u), n - 2u);
      const float t = u - float(k);
      const vec3 a = bundled.values[s0 + k].xyz - originals.values[s0 + k].xyz;
      const vec3 b = bundled.values[s0 + k + 1u].xyz - originals.values[s0 + k + 1u].xyz;
      shift = mix(a, b, t);
    }
    output_points.values[3u * i] = p.x + shift.x;
    output_points.values[3u * i + 1u] = p.y + shift.y;
    output_points.values[3u * i + 2u] = p.z + shift.z;
  }
}
