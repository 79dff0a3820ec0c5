#include "gpu/submit.h"

#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

// Frees the command buffer and fence on every path out of submitOnce.
struct OneShot {
  const VulkanContext& context;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  ~OneShot() {
    if (fence != VK_NULL_HANDLE) vkDestroyFence(context.device(), fence, nullptr);
    if (cmd != VK_NULL_HANDLE) vkFreeCommandBuffers(context.device(), context.commandPool(), 1, &cmd);
  }
};

constexpr uint64_t kTimeoutNs = 600ull * 1000 * 1000 * 1000;

}  // namespace

void submitOnce(const VulkanContext& context, const std::function<void(VkCommandBuffer)>& record) {
  OneShot shot{context};
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = context.commandPool();
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  throwIfFailed(vkAllocateCommandBuffers(context.device(), &alloc, &shot.cmd), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(shot.cmd, &begin));
  record(shot.cmd);
  VK_CHECK(vkEndCommandBuffer(shot.cmd));

  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  throwIfFailed(vkCreateFence(context.device(), &fence_info, nullptr, &shot.fence), "vkCreateFence");
  VkCommandBufferSubmitInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cmd_info.commandBuffer = shot.cmd;
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cmd_info;
  throwIfFailed(vkQueueSubmit2(context.queue(), 1, &submit, shot.fence), "vkQueueSubmit2");
  const VkResult wait = vkWaitForFences(context.device(), 1, &shot.fence, VK_TRUE, kTimeoutNs);
  if (wait == VK_TIMEOUT) {
    // The command buffer is still in use: wait for the device before freeing it.
    vkDeviceWaitIdle(context.device());
    throw Error("vulkan: GPU work did not finish within 600 s on " + context.info().name);
  }
  throwIfFailed(wait, "vkWaitForFences");
}

void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                   VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) {
  VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  barrier.srcStageMask = src_stage;
  barrier.srcAccessMask = src_access;
  barrier.dstStageMask = dst_stage;
  barrier.dstAccessMask = dst_access;
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.memoryBarrierCount = 1;
  dependency.pMemoryBarriers = &barrier;
  vkCmdPipelineBarrier2(cmd, &dependency);
}

void computeToComputeBarrier(VkCommandBuffer cmd) {
  memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

}  // namespace fibscope::gpu
