#include "render/gpu_fiblet_passes.h"

#include "shared/render_config.h"
#include "shared/render_push.h"

namespace fibscope {

FibletPasses createFibletPasses(const gpu::VulkanContext& context) {
  FibletPasses passes;
  try {
    passes.raster = gpu::createComputePipeline(context, "fiblet_raster.comp", sizeof(shader::FibletRasterPush));
    passes.resolve = gpu::createComputePipeline(context, "fiblet_resolve.comp", sizeof(shader::FibletResolvePush));
  } catch (...) {
    destroyFibletPasses(context, passes);
    throw;
  }
  return passes;
}

void destroyFibletPasses(const gpu::VulkanContext& context, FibletPasses& passes) {
  gpu::destroyComputePipeline(context, passes.resolve);
  gpu::destroyComputePipeline(context, passes.raster);
}

uint32_t pixelGroupsX(const GpuFrameTargets& frame) {
  return (frame.width + shader::kPixelGroupSize - 1) / shader::kPixelGroupSize;
}
uint32_t pixelGroupsY(const GpuFrameTargets& frame) {
  return (frame.height + shader::kPixelGroupSize - 1) / shader::kPixelGroupSize;
}

void recordFibletRasterAll(VkCommandBuffer cmd, const gpu::VulkanContext& context, const FibletPasses& passes,
                           const GpuDataset& dataset, const GpuFrameTargets& frame) {
  const uint32_t fiblets = dataset.block().fiblet_count;
  if (fiblets == 0) return;
  shader::FibletRasterPush push{};
  push.dataset = dataset.blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  push.list = 0;
  const gpu::DispatchGrid grid = gpu::dispatchGrid(context, fiblets);
  gpu::recordDispatch(cmd, passes.raster, push, grid.x, grid.y);
}

void recordFibletRasterList(VkCommandBuffer cmd, const FibletPasses& passes, const GpuDataset& dataset,
                            const GpuFrameTargets& frame, const gpu::Buffer& list) {
  shader::FibletRasterPush push{};
  push.dataset = dataset.blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  push.list = list.address;
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, passes.raster.pipeline);
  vkCmdPushConstants(cmd, passes.raster.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
  vkCmdDispatchIndirect(cmd, list.buffer, 0);
}

void recordFibletResolve(VkCommandBuffer cmd, const FibletPasses& passes, const GpuDataset& dataset,
                         const GpuFrameTargets& frame) {
  shader::FibletResolvePush push{};
  push.dataset = dataset.blockAddress();
  push.visibility = frame.visibility.address;
  push.gbuffer = frame.gbuffer.address;
  push.width = frame.width;
  push.height = frame.height;
  gpu::recordDispatch(cmd, passes.resolve, push, pixelGroupsX(frame), pixelGroupsY(frame));
}

}  // namespace fibscope
