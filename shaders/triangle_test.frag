// Solid colour from the push constants (GPU test of graphics pipelines).
#version 460
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

layout(push_constant, std430) uniform Push {
  uint64_t positions;
  float r, g, b, a;
} pc;

layout(location = 0) out vec4 colour;

void main() { colour = vec4(pc.r, pc.g, pc.b, pc.a); }
