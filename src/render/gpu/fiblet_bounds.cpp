#include "render/gpu/fiblet_bounds.h"

#include "gpu/submit.h"
#include "shared/cull_push.h"
#include "shared/render_config.h"

namespace fibscope {

FibletBoundsPass createFibletBoundsPass(const gpu::VulkanContext& context) {
  FibletBoundsPass pass;
  pass.bounds = gpu::createComputePipeline(context, "fiblet_bounds.comp", sizeof(shader::FibletBoundsPush),
                                           gpu::WorkgroupSize{shader::kCullGroupSize});
  return pass;
}

void destroyFibletBoundsPass(const gpu::VulkanContext& context, FibletBoundsPass& pass) {
  gpu::destroyComputePipeline(context, pass.bounds);
}

void recordFibletBounds(VkCommandBuffer cmd, const gpu::VulkanContext& context, const FibletBoundsPass& pass,
                        VkDeviceAddress dataset, VkDeviceAddress bounds, uint32_t fiblets) {
  if (fiblets == 0) return;
  shader::FibletBoundsPush push{};
  push.dataset = dataset;
  push.bounds = bounds;
  const gpu::DispatchGrid grid =
      gpu::dispatchGrid(context, (uint64_t(fiblets) + shader::kCullGroupSize - 1) / shader::kCullGroupSize);
  gpu::recordDispatch(cmd, pass.bounds, push, grid.x, grid.y);
}

void computeFibletBounds(const gpu::VulkanContext& context, VkDeviceAddress dataset, VkDeviceAddress bounds,
                         uint32_t fiblets) {
  if (fiblets == 0) return;
  FibletBoundsPass pass = createFibletBoundsPass(context);
  try {
    gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
      // The staged uploads of the records, table and block.
      gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
      recordFibletBounds(cmd, context, pass, dataset, bounds, fiblets);
      // For the culls of later submissions.
      gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT);
    });
  } catch (...) {
    destroyFibletBoundsPass(context, pass);
    throw;
  }
  destroyFibletBoundsPass(context, pass);
}

}  // namespace fibscope
