// The shading stages shared by every pipeline (DESIGN.md section 6,
// "Shading"): the G-buffer (and surface target) + camera block -> the
// RGBA8 image of the frame targets, with optional screen-space ambient
// occlusion:
//   tiles      shaders/tile_classify.comp  the 8 x 8 tiles with a covered pixel;
//                                          the passes below run on those only
//   ssao       shaders/ssao.comp       occlusion factor per pixel
//   ssao blur  shaders/ssao_blur.comp  depth-aware blur, x then y
//   shade      shaders/shade.comp      colour x lighting x occlusion -> RGBA8
//   fxaa       shaders/fxaa.comp       optional anti-aliasing of that image
// Formulas and push constants: shaders/shared/shade_push.h. The factories
// are in frame_stages.h; what else the stages share is here.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"
#include "render/render_settings.h"

namespace fibscope {

// Whether the SSAO passes run (and shade multiplies by their factor).
bool ssaoRuns(const RenderSettings& settings);

// The image shade writes: the frame's colour, or the scratch that FXAA
// reads into the colour.
inline bool fxaaRuns(const RenderSettings& settings) { return settings.fxaa; }

// RGBA8 of a colour in [0, 1] (clamped; A = 255), as the shaders store it.
uint32_t packRgba8(const std::array<float, 3>& color);

// FXAA of `input` (RGBA8 per pixel, width x height, made visible to
// compute reads before) into `output` (a different buffer of that size):
// the fxaa stage's pass, exposed for tests on hand-made images.
struct FxaaPass {
  gpu::ComputePipeline pipeline;  // fxaa.comp
};
FxaaPass createFxaaPass(const gpu::VulkanContext& context);
void destroyFxaaPass(const gpu::VulkanContext& context, FxaaPass& pass);
void recordFxaa(VkCommandBuffer cmd, const FxaaPass& pass, const gpu::Buffer& input, const gpu::Buffer& output,
                uint32_t width, uint32_t height);

}  // namespace fibscope
