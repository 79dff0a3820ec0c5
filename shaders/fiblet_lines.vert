// The geometry and tessellation fiblet pipelines' vertex shader (paper
// section 4.5): no vertex input, one vertex per fiblet. It only names the
// fiblet (the cull list's entry gl_VertexIndex, or gl_VertexIndex itself
// without a list); the decode is the next stage's (fiblet_lines.geom,
// fiblet_lines.tesc), which is what these pipelines compare.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/render_buffers.glsl"

layout(push_constant, std430) uniform Push { FibletDrawPush pc; };

layout(location = 0) out uint out_fiblet;

void main() {
  const uint index = uint(gl_VertexIndex);
  // (The draw's vertex count is the list's count.)
  out_fiblet = pc.list != 0ul ? FibletListRef(pc.list).fiblets[index] : index;
}
