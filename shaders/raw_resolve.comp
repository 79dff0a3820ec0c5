// Resolve for the raw-compute baseline: per pixel, the winning key's
// payload (the global index of the segment's first point) becomes a
// G-buffer texel: the chunk by binary search in the chunk table, the fiber
// by binary search in the streamline offsets of that chunk's streamlines,
// the segment as the point's index within its fiber, the tangent from the
// segment's two points (both in the chunk: chunks hold whole streamlines).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/raw_tractogram.glsl"
#include "glsl/tangent.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { RawResolvePush pc; };

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const uint64_t key = VisibilityRef(pc.visibility).keys[visibilityIndex(p.x, p.y, pc.width)];
  GBufferTexel texel;
  texel.depth = 1.0;
  texel.fiber = kNoFiberId;
  texel.segment = 0u;
  texel.tangent = 0u;
  if (key != 0xFFFFFFFFFFFFFFFFul) {
    const RawTractogram t = RawTractogramRef(pc.tractogram).t;
    const uint64_t point = visibilityPayload(key);
    const RawChunk c = rawChunk(t, rawChunkOfPoint(t, point));
    const uint fiber = rawStreamlineOfPoint(t, c, point);
    const uint64_t j = point - c.first_point;
    const vec3 d = rawChunkPoint(c, j + 1ul) - rawChunkPoint(c, j);
    texel.depth = visibilityDepth(key);
    texel.fiber = fiber;
    texel.segment = uint(point - RawOffsetsRef(t.offsets).values[fiber]);
    texel.tangent = dot(d, d) > 0.0 ? packTangent(normalize(d)) : 0u;
  }
  GBufferRef(pc.gbuffer).texels[index] = texel;
}
