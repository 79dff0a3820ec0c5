// Push constants of the post-effects pass (post_effects.comp; DESIGN.md
// section 6, "Shading"; FiberVisualizer section 12): RGBA8 in -> RGBA8 out
// (A = 255), after shading and ambient occlusion, before FXAA. Per pixel,
// on the stored values c in [0, 1] (k / 255), in the paper's order, each
// step clamped to [0, 1] as a chain of passes on an 8-bit target would be
// (but not rounded to 8 bits between the steps):
//   1. flattening to n levels (levels >= 2): c = round(c (n - 1)) / (n - 1),
//      so 0 and 1 stay and n = 256 leaves 8-bit values as they are;
//   2. contrast k: c = (c - 0.5) k + 0.5;
//   3. brightness d: c = c + d;
//   4. saturation s: L = 0.2125 R + 0.7154 G + 0.0721 B, c = L + s (c - L)
//      (0: grey, 1: unchanged);
//   5. sharpening by the 3 x 3 kernel [0 -a 0; -a 1+4a -a; 0 -a 0] (factor
//      a) over the image that steps 1-4 made, its borders clamped to the
//      edge (a pixel off the image reads the nearest pixel on it).
// The result is rounded to 8 bits (round half up). Neutral values: levels
// 0 or 1, contrast 1, brightness 0, saturation 1, sharpen 0 (the pass is
// not recorded at all when every effect is neutral: postEffectsRun).
#ifndef FIBSCOPE_SHADERS_SHARED_POST_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_POST_PUSH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define POST_CONST inline constexpr
#else
#define POST_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// Luminance weights of the saturation step (the paper's; Rec. 709 primaries).
POST_CONST float kPostLumaR = 0.2125f;
POST_CONST float kPostLumaG = 0.7154f;
POST_CONST float kPostLumaB = 0.0721f;

// Whether step 5 runs (constant_id; 1 when sharpen != 0): the variant
// without it reads one pixel instead of five.
POST_CONST uint kPostSpecSharpen = 0u;

struct PostPush {
  uint64_t color_in;   // uint per pixel (RGBA8, R in the low byte)
  uint64_t color_out;  // uint per pixel (written; a different buffer)
  uint width;
  uint height;
  uint levels;  // flattening: 0 or 1 off, else 2 .. 256
  float contrast;
  float brightness;
  float saturation;
  float sharpen;
  uint pad0;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::PostPush) == 48, "");
static_assert(offsetof(fibscope::shader::PostPush, width) == 16, "scalars follow the two addresses");
static_assert(offsetof(fibscope::shader::PostPush, sharpen) == 40, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_POST_PUSH_H
