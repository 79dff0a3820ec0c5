// Bundling, relaxation (shared/bundling.h; FiberVisualizer section 7):
// one invocation per sample pulls the bundled sample back towards its
// unbundled position, p' = o + alpha (p - o) (alpha = 1: fully bundled).
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
  const vec4 p = BundleVec4Ref(pc.src).values[i];
  const vec4 o = BundleVec4Ref(pc.field).values[i];
  BundleVec4Ref(pc.dst).values[i] = vec4(o.xyz + (p.xyz - o.xyz) * pc.step, p.w);
}
