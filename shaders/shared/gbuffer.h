// The G-buffer every pipeline writes (compute resolve, raw-compute resolve,
// lines) and the shading pass reads: one 16-byte texel per pixel, row-major,
// top row first, in a plain storage buffer (index = y * width + x).
//
// Surfaces (spheres, tubes, SVO streamtubes, anatomical slices) draw into a
// second target of the same size, the surface target (SurfaceTexel), each
// surface pass keeping the nearer of what is there and what it hits. The
// merge pass (surface_merge.comp) then puts every surface pixel nearer than
// the lines into the G-buffer, marked by kGBufferSurface in `segment`, so
// shading, AO and picking read one G-buffer; the shade pass reads the
// surface's normal and colour from the surface target at the same pixel.
//
// The lines pipeline renders the same four words into an R32G32B32A32_UINT
// colour attachment and copies it into this buffer, so all pipelines end in
// the same layout and every shading effect works with every pipeline.
#ifndef FIBSCOPE_SHADERS_SHARED_GBUFFER_H
#define FIBSCOPE_SHADERS_SHARED_GBUFFER_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define SHADER_CONST_U inline constexpr uint
#else
#define SHADER_CONST_U const uint
#endif

SHADER_NAMESPACE_BEGIN

struct GBufferTexel {
  float depth;    // clip depth z/w in [0, 1]; 1 where nothing is drawn
  uint fiber;     // streamline index; kNoFiberId (render_config.h) where nothing is drawn
  // Pipeline-specific position of the winning segment: the index of its
  // first point within its fiblet (compute) or within its fiber (lines,
  // raw-compute), below 2^31. Picking and tests use it; shading does not.
  // A surface pixel: kGBufferSurface | its kSurfaceSource*.
  uint segment;
  uint tangent;   // world-space unit tangent, octahedral, packSnorm2x16 (gbufferPackTangent)
};

// GBufferTexel::segment of a pixel the merge took from the surface target.
SHADER_CONST_U kGBufferSurface = 0x80000000u;

// Who drew a surface pixel (SurfaceTexel::source).
SHADER_CONST_U kSurfaceSourceSphere = 1u;  // analytic spheres (sphere_surface.comp)
SHADER_CONST_U kSurfaceSourceTube = 2u;    // spline tubes
SHADER_CONST_U kSurfaceSourceSvo = 3u;     // SVO streamtubes
SHADER_CONST_U kSurfaceSourceSlice = 4u;   // anatomical slices

// The surface target's texel (32 bytes). Cleared every frame that has
// surfaces to all words 0x3F800000: depth 1 (nothing nearer than the far
// plane), which the merge never takes (a surface wins only when strictly
// nearer than the lines' depth, itself at most 1).
struct SurfaceTexel {
  float depth;     // clip depth z/w in [0, 1]
  uint fiber;      // the fiber drawn (tubes), the object's id (spheres) or kNoFiberObject (slices)
  uint normal;     // world-space unit surface normal, packed as the tangents
  uint tangent;    // the fiber's tangent there (orientation colour), packed; 0 if none
  float position;  // along the fiber in points from its first (tubes, SVO); 0 if none
  uint color;      // RGBA8 own colour (slices: window/level) used when A > 0; else the colour mode's
  uint source;     // kSurfaceSource*
  uint pad0;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::GBufferTexel) == 16, "a G-buffer texel is 4 words");
static_assert(sizeof(fibscope::shader::SurfaceTexel) == 32, "a surface texel is 8 words");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_GBUFFER_H
