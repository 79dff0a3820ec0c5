// The G-buffer every pipeline writes (compute resolve, raw-compute resolve,
// lines) and the shading pass reads: one 16-byte texel per pixel, row-major,
// top row first, in a plain storage buffer (index = y * width + x).
//
// The lines pipeline renders the same four words into an R32G32B32A32_UINT
// colour attachment and copies it into this buffer, so all pipelines end in
// the same layout and every shading effect works with every pipeline.
#ifndef FIBSCOPE_SHADERS_SHARED_GBUFFER_H
#define FIBSCOPE_SHADERS_SHARED_GBUFFER_H

#include "shared/glsl_cpp.h"

SHADER_NAMESPACE_BEGIN

struct GBufferTexel {
  float depth;    // clip depth z/w in [0, 1]; 1 where nothing is drawn
  uint fiber;     // streamline index; kNoFiberId (render_config.h) where nothing is drawn
  // Pipeline-specific position of the winning segment: the index of its
  // first point within its fiblet (compute) or within its fiber (lines,
  // raw-compute). Picking and tests use it; shading does not.
  uint segment;
  uint tangent;   // world-space unit tangent, octahedral, packSnorm2x16 (gbufferPackTangent)
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::GBufferTexel) == 16, "a G-buffer texel is 4 words");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_GBUFFER_H
