// A cull list's count (shared/fiblet_list.h) as the indirect draws of the
// graphics fiblet pipelines, one vertex (a point, or a one-vertex patch)
// per listed fiblet: one VkDrawIndirectCommand{count, 1, 0, 0}, or, where
// draws are capped at `chunk` vertices (FibletGraphicsPass::
// patches_per_draw), command k draws slots k * chunk on (firstVertex; the
// vertex shader reads the list at gl_VertexIndex). One invocation per
// command.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x = 64) in;

layout(push_constant, std430) uniform Push { FibletDrawArgsPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer DrawArgsRef { uint words[4]; };

void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k >= pc.commands) return;
  const uint count = FibletListRef(pc.list).header.count;
  const uint first = pc.chunk == 0xFFFFFFFFu ? 0u : k * pc.chunk;
  DrawArgsRef args = DrawArgsRef(pc.args + uint64_t(k) * 16ul);
  args.words[0] = first < count ? min(pc.chunk, count - first) : 0u;  // vertexCount
  args.words[1] = 1u;                                                  // instanceCount
  args.words[2] = first;                                               // firstVertex: the vertex shader's list slot
  args.words[3] = 0u;                                                  // firstInstance
}
