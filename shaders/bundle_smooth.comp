// Bundling, smoothing (shared/bundling.h; FiberVisualizer section 7):
// one invocation per sample blends it with the mean of the samples of its
// fiber within m of it,
//   p' = (1 - phi) p + phi mean(p_j, |j - i| <= m),  m = min(k, i - s0, s1 - 1 - i),
// k = round(L / step) (bundling/bundle_setup.h): the window stays
// symmetric near the fiber's ends (a window cut on one side would pull
// the ends inward, shortening the fiber every iteration), so the end
// samples themselves move by advection only.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kBundleGroupSize

#include "glsl/bundling.glsl"

layout(push_constant, std430) uniform Push { BundleSamplePush pc; };

void main() {
  const uint i = bundleInvocation();
  if (i >= pc.sample_count) return;
  BundleVec4Ref src = BundleVec4Ref(pc.src);
  const vec4 p = src.values[i];
  const uint fiber = BundleUintsRef(pc.sample_fiber).values[i];
  const uint s0 = BundleUintsRef(pc.sample_offsets).values[fiber];
  const uint s1 = BundleUintsRef(pc.sample_offsets).values[fiber + 1u];
  vec4 result = p;
  const bool end = i == s0 || i + 1u == s1;
  if (!(end && pc.anchor_ends != 0u)) {
    const uint m = min(pc.window, min(i - s0, s1 - 1u - i));
    const uint lo = i - m;
    const uint hi = i + m;
    vec3 sum = vec3(0.0);
    for (uint j = lo; j <= hi; ++j) sum += src.values[j].xyz;
    const vec3 mean = sum / float(hi - lo + 1u);
    result = vec4(p.xyz * (1.0 - pc.step) + mean * pc.step, p.w);
  }
  BundleVec4Ref(pc.dst).values[i] = result;
}
