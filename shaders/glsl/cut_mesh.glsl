// The mesh cuts' per-fragment test (shared/cut_mesh.h), one definition for
// the compute rasters (raster_segment.glsl) and the lines' fragment shader.
#ifndef FIBSCOPE_GLSL_CUT_MESH_GLSL
#define FIBSCOPE_GLSL_CUT_MESH_GLSL

#include "glsl/render_buffers.glsl"

// Whether the cuts keep a fragment at pixel `index` (row-major) of
// `pixels` at clip depth `depth`.
bool cutMeshesKeep(CutMeshFrame cuts, uint pixels, uint index, float depth) {
  UintsRef words = UintsRef(cuts.depths);
  for (uint m = 0u; m < cuts.mesh_count; ++m) {
    const bool inside = cutInside(words.values[2u * m * pixels + index], words.values[(2u * m + 1u) * pixels + index], depth);
    if (inside == (((cuts.inside_bits >> m) & 1u) != 0u)) return false;
  }
  return true;
}

#endif
