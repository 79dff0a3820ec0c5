// Bundling, count (shared/bundling.h): one invocation per sample adds 1 to
// the voxel holding it (clamped into the grid). Integer atomics: the counts
// do not depend on the order, so bundling is deterministic.
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
  const uvec3 v = bundleVoxelOf(pc.grid, BundleVec4Ref(pc.src).values[i].xyz);
  atomicAdd(BundleUintsRef(pc.field).values[bundleVoxelIndex(pc.grid, v.x, v.y, v.z)], 1u);
}
