// One-shot command submission: record, submit, wait. For uploads, downloads,
// tests and tools; the renderer's frames use their own command buffers.
#pragma once

#include <vulkan/vulkan.h>

#include <functional>

#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

// Records `record` into a fresh primary command buffer, submits it to the
// context's queue and waits for it (up to 10 minutes). Throws Error when the
// device is lost or the work does not finish in time; exceptions thrown by
// `record` propagate (nothing is submitted then).
void submitOnce(const VulkanContext& context, const std::function<void(VkCommandBuffer)>& record);

// A memory barrier between two passes (synchronization2).
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
                   VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access);
// The barrier between two compute passes: every storage write and read of
// the earlier ones before any storage read or write of the later ones.
void computeToComputeBarrier(VkCommandBuffer cmd);

}  // namespace fibscope::gpu
