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
  // Shell sort (Ciura's gaps; the last pass, gap 1, an insertion sort):
  // most lists are a few words, but a dense whole brain's hold hundreds,
  // where an insertion sort's n^2 / 4 moves would dominate the build.
  const uint gaps[8] = uint[8](701u, 301u, 132u, 57u, 23u, 10u, 4u, 1u);
  for (uint g = 0u; g < 8u; ++g) {
    const uint gap = gaps[g];
    for (uint k = gap; k < n; ++k) {
      const uint v = WordsRef(pc.decoration).words[at + 1u + k];
      uint j = k;
      for (; j >= gap; j -= gap) {
        const uint w = WordsRef(pc.decoration).words[at + 1u + j - gap];
        if (w <= v) break;
        WordsRef(pc.decoration).words[at + 1u + j] = w;
      }
      WordsRef(pc.decoration).words[at + 1u + j] = v;
    }
  }
}
