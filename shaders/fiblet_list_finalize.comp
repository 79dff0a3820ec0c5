// Turns a fiblet list's count (shared/fiblet_list.h) into its indirect
// dispatch size: ceil(count / items_per_group) workgroups as a 2D grid no
// wider than the device allows (the consumers flatten it and skip indices
// past the count). One invocation.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/cull_push.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x = 1) in;

layout(push_constant, std430) uniform Push { FibletListFinalizePush pc; };

void main() {
  FibletListRef list = FibletListRef(pc.list);
  const uint groups = (list.header.count + pc.items_per_group - 1u) / pc.items_per_group;
  if (groups <= pc.max_groups_x) {
    list.header.dispatch_x = groups;
    list.header.dispatch_y = 1u;
  } else {
    list.header.dispatch_x = pc.max_groups_x;
    list.header.dispatch_y = (groups + pc.max_groups_x - 1u) / pc.max_groups_x;
  }
  list.header.dispatch_z = 1u;
}
