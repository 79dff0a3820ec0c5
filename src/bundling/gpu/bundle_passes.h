// The bundling passes (shared/bundling.h), one recording function each:
// its timestamp pair and trailing compute-to-compute barrier come from a
// gpu::PassScope, its push constants are size-checked at dispatch.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/compute_pipeline.h"
#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "shared/bundling.h"

namespace fibscope {

struct BundlePipelines {
  gpu::ComputePipeline resample, count, density, gradient, advect, smooth, relax, map_back, splat, structure_mean,
      structure;
};

// Throws Error when a pipeline cannot be made (none is left then).
BundlePipelines createBundlePipelines(const gpu::VulkanContext& context);
void destroyBundlePipelines(const gpu::VulkanContext& context, BundlePipelines& pipelines);

// Per fiber (push.fiber_count invocations).
void recordBundleResample(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                          const shader::BundleFiberPush& push, gpu::GpuTimer* timer);
void recordBundleMapBack(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                         const shader::BundleFiberPush& push, gpu::GpuTimer* timer);
// Per sample (push.sample_count invocations).
void recordBundleCount(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                       const shader::BundleSamplePush& push, gpu::GpuTimer* timer);
void recordBundleAdvect(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                        const shader::BundleSamplePush& push, gpu::GpuTimer* timer);
void recordBundleSmooth(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                        const shader::BundleSamplePush& push, gpu::GpuTimer* timer);
void recordBundleSplat(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                       const shader::BundleSamplePush& push, gpu::GpuTimer* timer);
void recordBundleRelax(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                       const shader::BundleSamplePush& push, gpu::GpuTimer* timer);
// Per voxel.
void recordBundleDensityAxis(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                             const shader::BundleGridPush& push, gpu::GpuTimer* timer);
void recordBundleGradient(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                          const shader::BundleGridPush& push, gpu::GpuTimer* timer);
// Per cell of the structure tensor: the mean density (push.grid the voxel
// grid, push.cell its cells), then the tensor (push.grid the cell grid).
void recordBundleStructureMean(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                               const shader::BundleGridPush& push, gpu::GpuTimer* timer);
void recordBundleStructure(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                           const shader::BundleGridPush& push, gpu::GpuTimer* timer);

}  // namespace fibscope
