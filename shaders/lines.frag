// Lines baseline: writes the G-buffer texel's four words (shared/gbuffer.h)
// into an R32G32B32A32_UINT attachment; the depth attachment (LESS) keeps
// the nearest fragment, and the pass copies the attachment into the
// G-buffer storage buffer. A mesh cut (shared/cut_mesh.h) discards the
// fragments it hides, by the same per-pixel rule as the compute rasters.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "glsl/raw_tractogram.glsl"
#include "glsl/cut_mesh.glsl"

layout(push_constant, std430) uniform Push { LinesPush pc; };

layout(location = 0) flat in uint in_fiber;
layout(location = 1) flat in uint in_segment;
layout(location = 2) flat in uint in_tangent;

layout(location = 0) out uvec4 texel;

void main() {
  const CameraBlock cam = CameraRef(pc.camera).camera;
  if (cam.mesh_cuts.mesh_count != 0u) {
    const uint width = uint(cam.viewport.x);
    if (!cutMeshesKeep(cam.mesh_cuts, width * uint(cam.viewport.y), uint(gl_FragCoord.y) * width + uint(gl_FragCoord.x),
                       gl_FragCoord.z))
      discard;
  }
  texel = uvec4(floatBitsToUint(gl_FragCoord.z), in_fiber, in_segment, in_tangent);
}
