// Compute pipelines from embedded SPIR-V. Shaders reach their buffers
// through buffer references (device addresses) in push constants, so a
// pipeline layout is only a push-constant range: no descriptor sets.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

struct ComputePipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  uint32_t push_constant_bytes = 0;
  std::string name;  // the shader, for messages
};

// `shader` names an embedded shader (e.g. "fiblet_decode_test.comp").
// `push_constant_bytes` is the size of the shader's push-constant block (a
// multiple of 4, at most the device's maxPushConstantsSize). Specialization
// constant i (constant_id = i) gets specialization[i]. Throws Error when the
// shader is unknown, the push constants are too large or the driver rejects
// the pipeline.
ComputePipeline createComputePipeline(const VulkanContext& context, std::string_view shader,
                                      uint32_t push_constant_bytes, std::span<const uint32_t> specialization = {});

// The workgroup size of a shader that declares it through
// shared/workgroup.h's specialisation constants.
struct WorkgroupSize {
  uint32_t x = 1, y = 1, z = 1;
};
// As above, and the shader's workgroup size is `local` (its constants
// WORKGROUP_SIZE_X_ID ... set to it).
ComputePipeline createComputePipeline(const VulkanContext& context, std::string_view shader,
                                      uint32_t push_constant_bytes, WorkgroupSize local,
                                      std::span<const uint32_t> specialization = {});
void destroyComputePipeline(const VulkanContext& context, ComputePipeline& pipeline);

// Binds the pipeline, pushes `push` (whose size must be the pipeline's
// push-constant size: a mismatch is a programming error and aborts) and
// dispatches groups_x * groups_y * groups_z workgroups.
void recordDispatch(VkCommandBuffer cmd, const ComputePipeline& pipeline, const void* push, uint32_t push_bytes,
                    uint32_t groups_x, uint32_t groups_y = 1, uint32_t groups_z = 1);
template <typename PushConstants>
void recordDispatch(VkCommandBuffer cmd, const ComputePipeline& pipeline, const PushConstants& push, uint32_t groups_x,
                    uint32_t groups_y = 1, uint32_t groups_z = 1) {
  recordDispatch(cmd, pipeline, &push, uint32_t(sizeof(PushConstants)), groups_x, groups_y, groups_z);
}

// The same from `indirect` at `offset` (a VkDispatchIndirectCommand the
// device wrote and made visible to indirect reads), with the same check of
// the push-constant size.
void recordDispatchIndirect(VkCommandBuffer cmd, const ComputePipeline& pipeline, const void* push, uint32_t push_bytes,
                            VkBuffer indirect, VkDeviceSize offset);
template <typename PushConstants>
void recordDispatchIndirect(VkCommandBuffer cmd, const ComputePipeline& pipeline, const PushConstants& push,
                            VkBuffer indirect, VkDeviceSize offset = 0) {
  recordDispatchIndirect(cmd, pipeline, &push, uint32_t(sizeof(PushConstants)), indirect, offset);
}

// Workgroups for `count` items as a 2D grid (x at most the device's limit);
// the shader flattens it as gl_WorkGroupID.y * gl_NumWorkGroups.x +
// gl_WorkGroupID.x and skips indices >= count. Throws Error when even the 2D
// grid is too small.
struct DispatchGrid {
  uint32_t x = 1, y = 1;
};
DispatchGrid dispatchGrid(const VulkanContext& context, uint64_t count);

}  // namespace fibscope::gpu
