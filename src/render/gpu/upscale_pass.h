// The upscale pass (shaders/upscale_color.comp): a shaded RGBA8 image from a
// smaller frame stretched bilinearly over a larger colour buffer. The viewer
// draws its coarse frames (camera moving, slow device) at half resolution
// through a second FrameRenderer and upscales them into the window's.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"

namespace fibscope {

struct UpscalePass {
  gpu::ComputePipeline pipeline;
};

// Throws Error when the pipeline cannot be created.
UpscalePass createUpscalePass(const gpu::VulkanContext& context);
void destroyUpscalePass(const gpu::VulkanContext& context, UpscalePass& pass);

// Records src (src_width x src_height RGBA8, its writes made visible to
// compute reads before) upscaled into dst (dst_width x dst_height; a
// different buffer). Throws Error for an empty size or buffers smaller than
// their images.
void recordUpscale(VkCommandBuffer cmd, const UpscalePass& pass, const gpu::Buffer& src, uint32_t src_width,
                   uint32_t src_height, const gpu::Buffer& dst, uint32_t dst_width, uint32_t dst_height);

}  // namespace fibscope
