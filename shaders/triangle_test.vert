// Vertices pulled from a buffer reference (no vertex input state), for the
// GPU test of graphics pipelines with dynamic rendering.
#version 460
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer Positions { vec2 xy[]; };

layout(push_constant, std430) uniform Push {
  uint64_t positions;  // clip-space x, y per vertex
  float r, g, b, a;
} pc;

void main() { gl_Position = vec4(Positions(pc.positions).xy[gl_VertexIndex], 0.5, 1.0); }
