// A cull list's count (shared/fiblet_list.h) as the indirect draw of the
// graphics fiblet pipelines: VkDrawIndirectCommand{count, 1, 0, 0}, one
// vertex (a point, or a one-vertex patch) per listed fiblet. One invocation.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x = 1) in;

layout(push_constant, std430) uniform Push { FibletDrawArgsPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer DrawArgsRef { uint words[4]; };

void main() {
  DrawArgsRef args = DrawArgsRef(pc.args);
  args.words[0] = FibletListRef(pc.list).header.count;
  args.words[1] = 1u;
  args.words[2] = 0u;
  args.words[3] = 0u;
}
