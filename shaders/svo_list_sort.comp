// SVO decoration lists, last step (shared/svo_build.h SvoListSortPush):
// one invocation per leaf writes its count word and sorts its list by
// segment index (the fill's atomic order is arbitrary; sorted, the lists
// are deterministic and equal the CPU reference's).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo_build.h"
#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kSvoTreeGroupSize

layout(push_constant, std430) uniform Push { SvoListSortPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer OffsetsRef { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer WordsRef { uint words[]; };

void main() {
  const uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  if (i >= pc.leaf_count) return;
  const uint at = OffsetsRef(pc.offsets).words[i];
  const uint n = OffsetsRef(pc.offsets).words[i + 1u] - at - 1u;
  WordsRef(pc.decoration).words[at] = n;
  for (uint k = 1u; k < n; ++k) {
    const uint v = WordsRef(pc.decoration).words[at + 1u + k];
    uint j = k;
    for (; j > 0u; --j) {
      const uint w = WordsRef(pc.decoration).words[at + j];
      if (w <= v) break;
      WordsRef(pc.decoration).words[at + 1u + j] = w;
    }
    WordsRef(pc.decoration).words[at + 1u + j] = v;
  }
}
