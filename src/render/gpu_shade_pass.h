// The shading passes shared by every pipeline (DESIGN.md section 6,
// "Shading"): G-buffer + camera block -> the RGBA8 image of the frame
// targets, with optional screen-space ambient occlusion.
//   tiles      shaders/tile_classify.comp  the 8 x 8 tiles with a covered pixel;
//                                          the passes below run on those only
//   ssao       shaders/ssao.comp       occlusion factor per pixel (scratch buffer)
//   ssao blur  shaders/ssao_blur.comp  depth-aware blur, x then y
//   shade      shaders/shade.comp      colour x lighting x occlusion -> RGBA8
//   fxaa       shaders/fxaa.comp       optional anti-aliasing of that image
// Formulas and push constants: shaders/shared/shade_push.h.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "render/gpu_frame_targets.h"
#include "render/render_settings.h"

namespace fibscope {

struct ShadePass {
  gpu::ComputePipeline tile_classify;  // tile_classify.comp
  gpu::ComputePipeline tile_finalize;  // fiblet_list_finalize.comp, on the tile list
  gpu::ComputePipeline ssao;       // ssao.comp
  gpu::ComputePipeline ssao_blur;  // ssao_blur.comp
  gpu::ComputePipeline shade;      // shade.comp
  gpu::ComputePipeline fxaa;       // fxaa.comp
  // Occlusion factor per pixel (float): ssao writes ao, the x blur ao_blur,
  // the y blur ao again, which shade reads.
  gpu::Buffer ao, ao_blur;
  // With FXAA, shade writes here (RGBA8 per pixel) and fxaa reads it into
  // the frame's colour buffer.
  gpu::Buffer fxaa_input;
  // A flag per tile, and the covered tiles (shared/fiblet_list.h layout:
  // the indirect dispatch of the tile passes, then the tile indices).
  gpu::Buffer tile_flags, tile_list;
  // Every colormap's table (colormap.h: allColormapTables), uploaded once.
  gpu::Buffer colormaps;
  uint32_t width = 0, height = 0;
  uint32_t max_groups_x = 0;  // maxComputeWorkGroupCount[0]: the tile list's grid
};

// The per-fiber inputs of shading (GpuScene::fiber_scalars and
// selection_bits), with the number of fibers they cover: fiber ids at or
// past it are treated as having no scalar and not being selected, so a
// buffer of another, smaller dataset is never read past its end.
struct ShadeFiberInputs {
  VkDeviceAddress fiber_scalars = 0;   // float per fiber, or 0
  VkDeviceAddress selection_bits = 0;  // uint words, or 0: no selection
  uint32_t fiber_count = 0;
};

// Pipelines and scratch buffers for a width x height frame. Throws Error
// when a pipeline cannot be created or memory runs out.
ShadePass createShadePass(const gpu::VulkanContext& context, uint32_t width, uint32_t height);
void destroyShadePass(const gpu::VulkanContext& context, ShadePass& pass);
// New scratch buffers for a new frame size (the device must not be using
// the old ones). Throws Error as createShadePass; the pass keeps its old
// buffers then.
void resizeShadePass(const gpu::VulkanContext& context, ShadePass& pass, uint32_t width, uint32_t height);

// Settings the shading passes reject: Error for an SSAO radius outside
// [0, 64] px, strength outside [0, 1], a range <= 0 mm, negative lighting
// coefficients or a shininess outside [1, 256], ao_scales outside [1, 4],
// a non-finite scalar range or one with max < min, a highlight colour
// outside [0, 1] or dim_unselected outside [0, 1]. Called by recordShade.
void validateShadeSettings(const RenderSettings& settings);

// Records the shading of `frame` (the camera block and the G-buffer must be
// written and made visible to compute reads before): the colour filled with
// the background, the covered tiles listed ("tiles"), the SSAO passes when
// settings.ssao (settings.ao_scales scales in the one "ssao" pass), then
// shade, then fxaa when settings.fxaa, with their own barriers between them
// and a timestamp pair per pass on `timer` when it is not null ("tiles",
// "ssao", "ssao blur", "shade", "fxaa"). The frame must have the pass's size.
// Throws Error for invalid settings or a size mismatch (nothing recorded
// then).
void recordShade(VkCommandBuffer cmd, const ShadePass& pass, const GpuFrameTargets& frame,
                 const RenderSettings& settings, gpu::GpuTimer* timer, const ShadeFiberInputs& fibers = {});

// Records FXAA of `input` (RGBA8 per pixel, width x height, made visible to
// compute reads before) into `output` (a different buffer of that size).
void recordFxaa(VkCommandBuffer cmd, const ShadePass& pass, const gpu::Buffer& input, const gpu::Buffer& output,
                uint32_t width, uint32_t height);

}  // namespace fibscope
