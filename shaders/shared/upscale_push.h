// Push constants of upscale_color.comp: a shaded RGBA8 image drawn at a
// lower resolution (the viewer's coarse frames while the camera moves)
// stretched bilinearly over a larger one. Pixel centres map onto each other
// (dst (x + 0.5) / dst_width == src (u + 0.5) / src_width), reads clamp to
// the edge, so a 2x upscale is the usual half-pixel bilinear filter.
#ifndef FIBSCOPE_SHADERS_SHARED_UPSCALE_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_UPSCALE_PUSH_H

#include "shared/glsl_cpp.h"

SHADER_NAMESPACE_BEGIN

struct UpscalePush {
  uint64_t src;  // uint (RGBA8, R in the low byte) per pixel, src_width x src_height, row-major
  uint64_t dst;  // the same layout, dst_width x dst_height (written)
  uint src_width;
  uint src_height;
  uint dst_width;
  uint dst_height;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::UpscalePush) == 32, "two addresses and four sizes");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_UPSCALE_PUSH_H
