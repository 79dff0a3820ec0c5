// SVO nodes (shared/svo_build.h SvoNodesPush): one invocation per node of
// a level writes its 8-byte SvoNode at its slot of the level's blocks:
// internal nodes point at their child block (blocks in code order, one per
// internal node), leaves at their decoration list with f at their centre.
// Slots no node takes stay kSvoNodeEmpty (the buffer is zeroed before).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"
#include "shared/svo_build.h"
#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kSvoTreeGroupSize

layout(push_constant, std430) uniform Push { SvoNodesPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) writeonly buffer NodesRef { SvoNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer WordsRef { uint words[]; };

void main() {
  const uint j = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  if (j >= pc.count) return;
  const uint index = pc.slots != 0ul ? pc.base + WordsRef(pc.slots).words[j] : 0u;
  SvoNode node;
  if (pc.leaf != 0u) {
    node.ref = kSvoNodeLeaf | WordsRef(pc.offsets).words[j];
    node.distance = uintBitsToFloat(WordsRef(pc.distances).words[j]);
  } else {
    node.ref = kSvoNodeInternal | (pc.child_base + 8u * j);
    node.distance = 0.0;
  }
  NodesRef(pc.nodes).nodes[index] = node;
}
