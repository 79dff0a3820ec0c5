// SVO leaves (shared/svo.h SvoCompactPush): one invocation per voxel of
// the slab; a voxel of the narrow band (|f| < band) appends its Morton
// code and f.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"
#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kSvoCompactGroupSize

layout(push_constant, std430) uniform Push { SvoCompactPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer FieldRef { uint keys[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer OutRef { uint items[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer CountRef { uint count; };

void main() {
  const uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  if (i >= pc.side * pc.side * pc.slab_depth) return;
  const uint key = FieldRef(pc.field).keys[i];
  if (key == kSvoFar) return;
  const float f = svoKeyFloat(key);
  if (!(abs(f) < pc.band)) return;
  const uint x = i % pc.side, y = (i / pc.side) % pc.side, z = pc.slab_z0 + i / (pc.side * pc.side);
  const uint slot = atomicAdd(CountRef(pc.count).count, 1u);
  if (slot >= pc.capacity) return;
  OutRef(pc.keys).items[slot] = svoMorton(x, y, z);
  OutRef(pc.values).items[slot] = floatBitsToUint(f);
}
