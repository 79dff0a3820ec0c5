// The shading stages shared by every pipeline (DESIGN.md section 6,
// "Shading"): the G-buffer (and surface target) + camera block -> the
// RGBA8 image of the frame targets, with optional screen-space ambient
// occlusion:
//   tiles      shaders/tile_classify.comp  the 8 x 8 tiles with a covered pixel;
//                                          the passes below run on those only
//   ssao       shaders/ssao.comp       occlusion factor per pixel
//   ssao blur  shaders/ssao_blur.comp  depth-aware blur, x then y
//   shade      shaders/shade.comp      colour x lighting x occlusion -> RGBA8
//   post       shaders/post_effects.comp  optional post effects (flattening,
//                                          contrast, brightness, saturation,
//                                          sharpening) of that image
//   fxaa       shaders/fxaa.comp       optional anti-aliasing of the result
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

// Whether the SSAO passes run (and shade multiplies by their factor):
// ambient occlusion on, by the screen-space method.
bool ssaoRuns(const RenderSettings& settings);

inline bool fxaaRuns(const RenderSettings& settings) { return settings.fxaa; }
// Whether the post-effects pass runs: some effect is not at its neutral
// value (shared/post_push.h). When none is, the pass is not recorded.
bool postEffectsRun(const RenderSettings& settings);

// Where the image goes between the optional passes, so that no pass reads
// the buffer it writes and the last one writes the frame's colour:
//   neither        shade -> color
//   post or FXAA   shade -> shaded -> color
//   both           shade -> color -> (post) shaded -> (FXAA) color
enum class ShadeTarget : uint8_t { Color, Shaded };
// The buffer shade writes (and the tiles stage fills with the background).
ShadeTarget shadeTarget(const RenderSettings& settings);
// The post pass's input and output.
ShadeTarget postInput(const RenderSettings& settings);
ShadeTarget postOutput(const RenderSettings& settings);

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

// The post effects of `input` (RGBA8 per pixel, width x height, made
// visible to compute reads before) into `output` (a different buffer of
// that size) with the settings' flatten, contrast, brightness, saturation
// and sharpen: the post stage's pass, exposed for tests on hand-made images.
struct PostPass {
  // post_effects.comp without and with sharpening (kPostSpecSharpen).
  std::array<gpu::ComputePipeline, 2> pipelines;
};
PostPass createPostPass(const gpu::VulkanContext& context);
void destroyPostPass(const gpu::VulkanContext& context, PostPass& pass);
void recordPostEffects(VkCommandBuffer cmd, const PostPass& pass, const gpu::Buffer& input,
                       const gpu::Buffer& output, uint32_t width, uint32_t height, const RenderSettings& settings);

}  // namespace fibscope
