// The raw-compute baseline (DESIGN.md section 6; the role of the paper's
// point-cloud compute column): shaders/raw_raster.comp rasterises every
// segment of the uncompressed float vertices into the 64-bit visibility
// buffer with the pixel rule of the fiblet raster, no culling, and
// shaders/raw_resolve.comp turns the winning keys into G-buffer texels
// (finding each key's chunk by binary search in the chunk table).
//
// Recording functions bind, push and dispatch only; the frame renderer
// places the barriers and timestamps.
#pragma once

#include <vulkan/vulkan.h>

#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/raw_tractogram.h"

namespace fibscope {

struct RawPasses {
  gpu::ComputePipeline raster;   // raw_raster.comp
  gpu::ComputePipeline resolve;  // raw_resolve.comp
};

RawPasses createRawPasses(const gpu::VulkanContext& context);
void destroyRawPasses(const gpu::VulkanContext& context, RawPasses& passes);

// Every segment (of the fiber filter's kept streamlines: `kept_points`,
// GpuScene::kept_point_bits, 0 for all): one dispatch per chunk of points,
// kRawRasterGroupSize invocations per workgroup on a 2D grid.
void recordRawRaster(VkCommandBuffer cmd, const gpu::VulkanContext& context, const RawPasses& passes,
                     const GpuRawTractogram& tractogram, const GpuFrameTargets& frame, VkDeviceAddress kept_points = 0);
void recordRawResolve(VkCommandBuffer cmd, const RawPasses& passes, const GpuRawTractogram& tractogram,
                      const GpuFrameTargets& frame);

}  // namespace fibscope
