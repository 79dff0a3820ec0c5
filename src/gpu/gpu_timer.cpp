#include "gpu/gpu_timer.h"

#include <cstdio>
#include <cstdlib>

#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

[[noreturn]] void misuse(const char* what) {
  std::fprintf(stderr, "fibscope: fatal: GpuTimer: %s\n", what);
  std::abort();
}

}  // namespace

GpuTimer createGpuTimer(const VulkanContext& context, uint32_t max_passes) {
  const uint32_t bits = context.info().timestamp_valid_bits;
  if (bits == 0) throw Error("vulkan: " + context.info().name + " has no timestamps on its queue");
  GpuTimer timer;
  timer.capacity = max_passes;
  timer.period_ns = context.limits().timestampPeriod;
  timer.valid_mask = bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = 2 * max_passes;
  throwIfFailed(vkCreateQueryPool(context.device(), &info, nullptr, &timer.pool), "vkCreateQueryPool");
  return timer;
}

void destroyGpuTimer(const VulkanContext& context, GpuTimer& timer) {
  if (timer.pool != VK_NULL_HANDLE) vkDestroyQueryPool(context.device(), timer.pool, nullptr);
  timer = GpuTimer{};
}

void resetGpuTimer(VkCommandBuffer cmd, GpuTimer& timer) {
  vkCmdResetQueryPool(cmd, timer.pool, 0, 2 * timer.capacity);
  timer.names.clear();
  timer.open = false;
}

void beginPass(VkCommandBuffer cmd, GpuTimer& timer, const std::string& name) {
  if (timer.open) misuse("beginPass inside a pass");
  if (timer.names.size() >= timer.capacity) misuse("more passes than the timer was created for");
  // ALL_COMMANDS: the timestamp is taken once every earlier command is done.
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timer.pool, uint32_t(2 * timer.names.size()));
  timer.names.push_back(name);
  timer.open = true;
}

void endPass(VkCommandBuffer cmd, GpuTimer& timer) {
  if (!timer.open) misuse("endPass without beginPass");
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, timer.pool, uint32_t(2 * timer.names.size() - 1));
  timer.open = false;
}

std::vector<PassTime> readGpuTimer(const VulkanContext& context, const GpuTimer& timer) {
  if (timer.open) misuse("readGpuTimer with a pass still open");
  std::vector<PassTime> times;
  if (timer.names.empty()) return times;
  std::vector<uint64_t> stamps(2 * timer.names.size());
  throwIfFailed(
      vkGetQueryPoolResults(context.device(), timer.pool, 0, uint32_t(stamps.size()), stamps.size() * sizeof(uint64_t),
                            stamps.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
      "vkGetQueryPoolResults");
  for (size_t i = 0; i < timer.names.size(); ++i) {
    // Masked difference: counters with fewer than 64 valid bits wrap.
    const uint64_t ticks = (stamps[2 * i + 1] - stamps[2 * i]) & timer.valid_mask;
    times.push_back({timer.names[i], double(ticks) * timer.period_ns * 1e-6});
  }
  return times;
}

}  // namespace fibscope::gpu
