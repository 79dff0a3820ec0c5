// The distance field's ordered keys (svo_voxelize.comp's atomicMin union)
// -> floats clamped to the band, in place (shared/distance_field.h
// DfFinalizePush): kSvoFar, no tube within the band, becomes the band.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/distance_field.h"
#include "shared/svo.h"
#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kDfFinalizeGroupSize

layout(push_constant, std430) uniform Push { DfFinalizePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer FieldRef { uint words[]; };

void main() {
  const uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  if (i >= pc.count) return;
  const uint key = FieldRef(pc.field).words[i];
  const float f = key == kSvoFar ? pc.band : min(svoKeyFloat(key), pc.band);
  FieldRef(pc.field).words[i] = floatBitsToUint(f);
}
