// dst[i] = src[i] * 3 + 1 for i < count, through device addresses in push
// constants: proves that buffer references reach the right memory (GPU
// context test).
#version 460
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

layout(local_size_x = 64) in;

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Source { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer Destination { uint values[]; };

layout(push_constant, std430) uniform Push {
  uint64_t src;
  uint64_t dst;
  uint count;
  uint pad;
} pc;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i < pc.count) Destination(pc.dst).values[i] = Source(pc.src).values[i] * 3u + 1u;
}
