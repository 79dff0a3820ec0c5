// One pass of a frame as a scope: its timestamp pair (gpu_timer.h) and the
// barrier that makes its writes visible to what follows, written by one
// object, so that no pass places them by hand and none is forgotten:
//
//   {
//     gpu::PassScope pass(cmd, timer, "resolve", gpu::kComputeToCompute);
//     gpu::recordDispatch(cmd, pipeline, push, groups_x, groups_y);
//   }  // end timestamp, then the barrier
#pragma once

#include <vulkan/vulkan.h>

#include <string>

#include "gpu/gpu_timer.h"

namespace fibscope::gpu {

// A memory barrier (synchronization2): the accesses of src_stage before the
// accesses of dst_stage. All zero: none.
struct PassBarrier {
  VkPipelineStageFlags2 src_stage = 0;
  VkAccessFlags2 src_access = 0;
  VkPipelineStageFlags2 dst_stage = 0;
  VkAccessFlags2 dst_access = 0;
};

inline constexpr VkAccessFlags2 kStorageReadWrite =
    VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
// Nothing after the pass (its successor synchronises, or nothing follows).
inline constexpr PassBarrier kNoBarrier{};
// Compute storage writes and reads before the next compute pass's.
inline constexpr PassBarrier kComputeToCompute{VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, kStorageReadWrite,
                                               VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, kStorageReadWrite};
// Compute writes before indirect dispatches that read them as commands and
// the compute passes that read them as storage.
inline constexpr PassBarrier kComputeToIndirect{
    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
    VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
    VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT};
// Transfers (fills, updates, copies) before compute passes.
inline constexpr PassBarrier kTransferToCompute{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, kStorageReadWrite};

// Records `barrier` (nothing for kNoBarrier).
void recordBarrier(VkCommandBuffer cmd, const PassBarrier& barrier);

class PassScope {
 public:
  // Begins the pass `name` on `timer` (none when null: a pass recorded
  // outside a timed frame, as tests do).
  PassScope(VkCommandBuffer cmd, GpuTimer* timer, const std::string& name, const PassBarrier& after);
  // Ends the pass, then records the barrier.
  ~PassScope();
  PassScope(const PassScope&) = delete;
  PassScope& operator=(const PassScope&) = delete;

 private:
  VkCommandBuffer cmd_;
  GpuTimer* timer_;
  PassBarrier after_;
};

}  // namespace fibscope::gpu
