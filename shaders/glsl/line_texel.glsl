// The fragment rule shared by the graphics pipelines that draw lines into
// the G-buffer's R32G32B32A32_UINT attachment (lines.frag for the raw
// baseline, fiblet_lines.frag for the geometry and tessellation fiblet
// pipelines): the texel's four words (shared/gbuffer.h) from the fragment's
// depth and the flat fiber / segment / tangent, and a mesh cut
// (shared/cut_mesh.h) discards the fragments it hides, by the same
// per-pixel rule as the compute rasters. The depth attachment (LESS) keeps
// the nearest fragment.
#ifndef FIBSCOPE_GLSL_LINE_TEXEL_GLSL
#define FIBSCOPE_GLSL_LINE_TEXEL_GLSL

#include "glsl/render_buffers.glsl"
#include "glsl/cut_mesh.glsl"

// Discards the fragment where a mesh cut hides it; else its texel.
uvec4 lineTexel(uint64_t camera, uint fiber, uint segment, uint tangent) {
  const CameraBlock cam = CameraRef(camera).camera;
  if (cam.mesh_cuts.mesh_count != 0u) {
    const uint width = uint(cam.viewport.x);
    if (!cutMeshesKeep(cam.mesh_cuts, width * uint(cam.viewport.y), uint(gl_FragCoord.y) * width + uint(gl_FragCoord.x),
                       gl_FragCoord.z))
      discard;
  }
  return uvec4(floatBitsToUint(gl_FragCoord.z), fiber, segment, tangent);
}

#endif
