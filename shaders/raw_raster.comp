// Raw-compute baseline raster (DESIGN.md section 6; the role of the paper's
// point-cloud compute column): one invocation per segment j -> j + 1 of the
// uncompressed float vertices of one chunk (one dispatch per chunk), no
// culling, the same pixel rule and 64-bit visibility keys as the fiblet
// raster (glsl/raster_segment.glsl). Payload: the global index of the
// segment's first point (shared/render_config.h). A segment whose first
// point ends its streamline joins two streamlines and is skipped; chunks
// hold whole streamlines, so no segment crosses from one chunk to the next.
//
// Per-chunk dispatches rather than a search for the chunk of each segment:
// the chunk is uniform over the dispatch (one cached load of its entry), so
// the hot loop costs what it did with one buffer; a search would add
// log2(chunks) dependent loads to every one of 0.43 G segments.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared/workgroup.h"
#include "glsl/raw_tractogram.glsl"
#include "glsl/raster_segment.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kRawRasterGroupSize

layout(push_constant, std430) uniform Push { RawRasterPush pc; };

void main() {
  const RawChunk c = rawChunk(RawTractogramRef(pc.tractogram).t, pc.chunk);
  const uint64_t group = uint64_t(gl_WorkGroupID.y) * uint64_t(gl_NumWorkGroups.x) + uint64_t(gl_WorkGroupID.x);
  const uint64_t j = group * uint64_t(gl_WorkGroupSize.x) + uint64_t(gl_LocalInvocationID.x);
  if (j + 1ul >= c.point_count) return;
  if (rawChunkPointEndsStreamline(c, j)) return;
  if (pc.kept_points != 0ul) {
    const uint64_t i = c.first_point + j;
    if (((UintsRef(pc.kept_points).values[uint(i >> 5ul)] >> uint(i & 31ul)) & 1u) == 0u) return;
  }
  const CameraBlock cam = CameraRef(pc.camera).camera;
  rasterSegment(VisibilityRef(pc.visibility), cam, rawChunkPoint(c, j), rawChunkPoint(c, j + 1ul), c.first_point + j);
}
