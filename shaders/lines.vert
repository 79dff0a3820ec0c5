// Lines baseline (DESIGN.md section 6; the paper's "basic OpenGL" column):
// the uncompressed float vertices drawn as line strips, one indirect draw
// per streamline (firstInstance = the streamline index, firstVertex = 0),
// recorded chunk by chunk with the chunk in the push constants, vertices
// pulled from that chunk's buffer through buffer references (no vertex
// input state).
// Writes, flat from the provoking (first) vertex of each segment, what the
// G-buffer texel needs besides the depth.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "glsl/raw_tractogram.glsl"
#include "glsl/tangent.glsl"

layout(push_constant, std430) uniform Push { LinesPush pc; };

// The cuts' clip planes, in world space: the clipper cuts each line where
// a distance crosses 0 (unused planes pass everything).
out float gl_ClipDistance[kMaxFrameClipPlanes];

layout(location = 0) flat out uint out_fiber;
layout(location = 1) flat out uint out_segment;
layout(location = 2) flat out uint out_tangent;

void main() {
  const RawTractogram t = RawTractogramRef(pc.tractogram).t;
  const uint fiber = uint(gl_InstanceIndex);
  const uint vertex = uint(gl_VertexIndex);  // within the streamline: the draw's firstVertex is 0
  RawOffsetsRef offsets = RawOffsetsRef(t.offsets);
  const uint64_t first = offsets.values[fiber];
  const uint64_t count = offsets.values[fiber + 1u] - first;
  // The streamline lies wholly in the draw's chunk.
  const RawChunk c = rawChunk(t, pc.chunk);
  const uint64_t j = first - c.first_point + uint64_t(vertex);
  const vec3 p = rawChunkPoint(c, j);
  const CameraBlock cam = CameraRef(pc.camera).camera;
  gl_Position = cameraTransformPoint(cam.view_projection, p);
  const uint planes = uint(cam.cuts.x);
  for (uint i = 0u; i < kMaxFrameClipPlanes; ++i)
    gl_ClipDistance[i] = i < planes ? dot(cam.clip_world[i].xyz, p) + cam.clip_world[i].w : 1.0;
  // A streamline the fiber filter dropped: every vertex beyond the far
  // plane, so the clipper removes each of its segments whole.
  if (pc.kept != 0ul && ((UintsRef(pc.kept).values[fiber >> 5u] >> (fiber & 31u)) & 1u) == 0u)
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
  // The segment vertex -> vertex + 1; the last vertex of a strip provokes
  // no segment.
  uint tangent = 0u;
  if (uint64_t(vertex) + 1ul < count) {
    const vec3 d = rawChunkPoint(c, j + 1ul) - p;
    if (dot(d, d) > 0.0) tangent = packTangent(normalize(d));
  }
  out_fiber = fiber;
  out_segment = vertex;
  out_tangent = tangent;
}
