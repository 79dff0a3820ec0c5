// Raw-compute baseline raster (DESIGN.md section 6; the role of the paper's
// point-cloud compute column): one invocation per segment i -> i + 1 of the
// uncompressed float vertices, no culling, the same pixel rule and 64-bit
// visibility keys as the fiblet raster (glsl/raster_segment.glsl). Payload:
// the global index of the segment's first point (shared/render_config.h).
// A segment whose first point ends its streamline joins two streamlines and
// is skipped.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "glsl/raw_tractogram.glsl"
#include "glsl/raster_segment.glsl"

layout(local_size_x = 64) in;  // kRawRasterGroupSize

layout(push_constant, std430) uniform Push { RawRasterPush pc; };

void main() {
  const RawTractogram t = RawTractogramRef(pc.tractogram).t;
  const uint64_t group = uint64_t(gl_WorkGroupID.y) * uint64_t(gl_NumWorkGroups.x) + uint64_t(gl_WorkGroupID.x);
  const uint64_t i = group * uint64_t(gl_WorkGroupSize.x) + uint64_t(gl_LocalInvocationID.x);
  if (i + 1ul >= t.point_count) return;
  if (rawPointEndsStreamline(t, i)) return;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  rasterSegment(VisibilityRef(pc.visibility), cam, rawPoint(t, i), rawPoint(t, i + 1ul), i);
}
