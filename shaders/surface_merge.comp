// Surface target -> G-buffer (shared/surface_push.h): a surface pixel
// strictly nearer than the lines' replaces the lines' texel, marked as a
// surface's (kGBufferSurface | source), so that shading, SSAO and picking
// read one G-buffer whatever drew the lines (compute, raw-compute, lines)
// and whatever drew the surfaces. A translucent slice (alpha < 255) over a
// drawn pixel leaves it: the shade pass blends the slice over it.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/surface_push.h"
#include "shared/workgroup.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { SurfaceMergePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SurfaceRef { SurfaceTexel texels[]; };

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const SurfaceTexel s = SurfaceRef(pc.surface).texels[index];
  GBufferRef gbuffer = GBufferRef(pc.gbuffer);
  const GBufferTexel behind = gbuffer.texels[index];
  if (!(s.depth < behind.depth)) return;
  if (s.source == kSurfaceSourceSlice && (s.color >> 24) < 255u && behind.fiber != kNoFiberId) return;
  GBufferTexel texel;
  texel.depth = s.depth;
  texel.fiber = s.fiber;
  texel.segment = kGBufferSurface | s.source;
  texel.tangent = s.tangent;
  gbuffer.texels[index] = texel;
}
