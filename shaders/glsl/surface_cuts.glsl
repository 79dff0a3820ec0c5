// The frame's cuts (DESIGN.md section 2) on a surface hit: the spline
// tubes' ray casters (tube_raycast.comp, tube_box.frag) and the
// tessellated tubes' fragments (tube_tess.frag; their clip planes also by
// gl_ClipDistance in tube_tess.tese) keep a hit only where every clip
// plane (the user's and the slab's) keeps its world point and no mesh cut
// hides it, the lines' per-pixel rule (line_texel.glsl, the compute
// rasters). Tubes are clipped, not dropped: a cut tube shows its surface up
// to the plane (open, its inside not drawn).
#ifndef FIBSCOPE_GLSL_SURFACE_CUTS_GLSL
#define FIBSCOPE_GLSL_SURFACE_CUTS_GLSL

#include "glsl/render_buffers.glsl"
#include "glsl/cut_mesh.glsl"

bool surfaceCutsKeep(CameraBlock cam, vec3 p, uint pixel_index, float depth) {
  const uint planes = min(uint(cam.cuts.x), kMaxFrameClipPlanes);
  for (uint i = 0u; i < planes; ++i)
    if (dot(cam.clip_world[i].xyz, p) + cam.clip_world[i].w < 0.0) return false;
  if (cam.mesh_cuts.mesh_count == 0u) return true;
  return cutMeshesKeep(cam.mesh_cuts, uint(cam.viewport.x) * uint(cam.viewport.y), pixel_index, depth);
}

#endif
