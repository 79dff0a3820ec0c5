// GPU time per named pass from timestamp queries: a pair of timestamps
// around each pass, read back after the work has finished.
#pragma once

#include <vulkan/vulkan.h>

#include <string>
#include <vector>

#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

struct PassTime {
  std::string name;
  double ms = 0;
};

struct GpuTimer {
  VkQueryPool pool = VK_NULL_HANDLE;
  uint32_t capacity = 0;           // passes
  std::vector<std::string> names;  // passes begun since the last reset
  bool open = false;               // a pass is begun and not ended
  double period_ns = 0;
  uint64_t valid_mask = 0;
};

// A timer for up to `max_passes` passes per submission. Throws Error when
// the device's queue has no timestamps.
GpuTimer createGpuTimer(const VulkanContext& context, uint32_t max_passes);
void destroyGpuTimer(const VulkanContext& context, GpuTimer& timer);

// Records the reset of every query; call before the first pass of a
// submission (outside a render pass).
void resetGpuTimer(VkCommandBuffer cmd, GpuTimer& timer);
// Timestamps after all earlier commands and after the pass's commands.
// Passes do not nest; more than max_passes passes, or end without begin,
// abort (programming errors).
void beginPass(VkCommandBuffer cmd, GpuTimer& timer, const std::string& name);
void endPass(VkCommandBuffer cmd, GpuTimer& timer);

// Milliseconds of each pass, in the order they were begun. Call after the
// submission has completed (waits for the results otherwise).
std::vector<PassTime> readGpuTimer(const VulkanContext& context, const GpuTimer& timer);

}  // namespace fibscope::gpu
