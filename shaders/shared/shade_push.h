// Push constants of the shading passes (DESIGN.md section 6, "Shading"):
// G-buffer (shared/gbuffer.h) + camera block -> RGBA8, optionally through
// screen-space ambient occlusion. One struct per pass; the pass's shader file
// names it. Buffers are device addresses; the uint64_t members come first
// and the rest are 4-byte scalars, so std430 and C++ agree.
//
//   ssao.comp       G-buffer depth -> raw ambient-occlusion factor per pixel
//   ssao_blur.comp  depth-aware separable blur of that factor (run twice: x, y)
//   shade.comp      colour x lighting x ambient occlusion -> RGBA8
#ifndef FIBSCOPE_SHADERS_SHARED_SHADE_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_SHADE_PUSH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define SHADE_CONST inline constexpr
#else
#define SHADE_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// ShadePush::color_mode (RenderSettings::color).
SHADE_CONST uint kShadeColorSolid = 0u;
SHADE_CONST uint kShadeColorOrientation = 1u;
SHADE_CONST uint kShadeColorPerFiber = 2u;
// ShadePush::lighting (RenderSettings::lighting).
SHADE_CONST uint kShadeLightingNone = 0u;
SHADE_CONST uint kShadeLightingIlluminated = 1u;

// Neighbours sampled per pixel by ssao.comp (a Vogel spiral, rotated per
// pixel), and the blur's half width in pixels.
SHADE_CONST uint kSsaoSamples = 16u;
SHADE_CONST uint kSsaoBlurRadius = 4u;

// The headlight: the direction towards the light in VIEW space (x right,
// y up, +z towards the viewer), a little above and to the left of the eye so
// that lines facing the viewer are not all equally lit. Not normalised here
// (shared code does no sqrt); the shaders and the tests normalise it.
SHADE_CONST float kShadeLightViewX = -0.35f;
SHADE_CONST float kShadeLightViewY = 0.45f;
SHADE_CONST float kShadeLightViewZ = 1.0f;

// ssao.comp: per covered pixel, the fraction of kSsaoSamples neighbours
// within radius_px that lie nearer the camera than the pixel by more than
// epsilon_mm and less than range_mm (a smooth falloff ends at range_mm),
// weighted by closeness; ao = 1 - strength * fraction. Empty pixels get 1.
struct SsaoPush {
  uint64_t camera;   // CameraBlock: depth_range linearises the clip depth
  uint64_t gbuffer;  // GBufferTexel per pixel
  uint64_t ao;       // float per pixel (written)
  uint width;
  uint height;
  float radius_px;
  float epsilon_mm;
  float range_mm;
  float strength;
};

// ssao_blur.comp: ao_out = the average of ao_in over the 2 * kSsaoBlurRadius
// + 1 pixels along (step_x, step_y), weighted by a Gaussian and counting only
// covered pixels whose view depth is within depth_tolerance_mm of the
// centre's. Empty pixels copy their value.
struct SsaoBlurPush {
  uint64_t camera;
  uint64_t gbuffer;
  uint64_t ao_in;   // float per pixel
  uint64_t ao_out;  // float per pixel (written)
  uint width;
  uint height;
  int step_x;  // (1, 0): horizontal pass, (0, 1): vertical pass
  int step_y;
  float depth_tolerance_mm;
  uint pad0;
};

// shade.comp: per pixel, base colour (color_mode) times lighting, times the
// ambient-occlusion factor when ao != 0, packed as RGBA8 (R in the low byte,
// A = 255); empty pixels get the background colour. Illuminated lines
// (Zoeckler, Stalling, Hege 1996) with T the tangent, L the light and V the
// direction towards the eye:
//   diffuse  = sqrt(1 - (L.T)^2)
//   specular = max(0, sqrt(1 - (L.T)^2) sqrt(1 - (V.T)^2) - (L.T)(V.T))^shininess
//   colour   = base * (ambient + diffuse_k * diffuse) + specular_k * specular
struct ShadePush {
  uint64_t camera;
  uint64_t gbuffer;
  uint64_t ao;     // float per pixel, or 0: no ambient occlusion
  uint64_t color;  // uint per pixel (written)
  uint width;
  uint height;
  uint color_mode;
  uint lighting;
  float solid_r, solid_g, solid_b;
  float background_r, background_g, background_b;
  float ambient;
  float diffuse;
  float specular;
  float shininess;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::SsaoPush) == 48, "");
static_assert(sizeof(fibscope::shader::SsaoBlurPush) == 56, "");
static_assert(sizeof(fibscope::shader::ShadePush) == 88, "");
static_assert(offsetof(fibscope::shader::ShadePush, width) == 32, "scalars follow the four addresses");
static_assert(offsetof(fibscope::shader::ShadePush, shininess) == 84, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_SHADE_PUSH_H
