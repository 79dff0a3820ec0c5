// SVO tree levels (shared/svo_build.h SvoLevelPush; Baert et al.,
// bottom-up): over one level's sorted codes, phase 0 flags each node
// whose parent (code >> 3) differs from the previous node's; after the
// exclusive scan of the flags (each node's parent rank), phase 1 writes
// the parent level's codes and each node's slot in the parent level's
// blocks.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo_build.h"
#include "shared/workgroup.h"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kSvoTreeGroupSize

layout(push_constant, std430) uniform Push { SvoLevelPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer CodesRef { uint codes[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer WordsRef { uint words[]; };

void main() {
  const uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationID.x;
  if (i > pc.count) return;
  if (i == pc.count) {  // the scan's total word
    if (pc.phase == 0u) WordsRef(pc.ranks).words[i] = 0u;
    return;
  }
  const uint code = CodesRef(pc.codes).codes[i];
  const bool first = i == 0u || (CodesRef(pc.codes).codes[i - 1u] >> 3u) != (code >> 3u);
  if (pc.phase == 0u) {
    WordsRef(pc.ranks).words[i] = first ? 1u : 0u;
    return;
  }
  // The exclusive scan counts the parents before this node's.
  const uint parent = WordsRef(pc.ranks).words[i] + (first ? 0u : 0xFFFFFFFFu);
  if (first) WordsRef(pc.parents).words[parent] = code >> 3u;
  WordsRef(pc.ranks).words[i] = 8u * parent + (code & 7u);
}
