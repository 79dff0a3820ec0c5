#include "gpu/compute_pipeline.h"

#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include "gpu/shader_library.h"
#include "shared/workgroup.h"
#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

ComputePipeline createPipeline(const VulkanContext& context, std::string_view shader, uint32_t push_constant_bytes,
                               std::span<const uint32_t> specialization, const WorkgroupSize* local) {
  const std::span<const uint32_t> words = shaderWords(shader);
  ComputePipeline result;
  result.name = std::string(shader);
  result.push_constant_bytes = push_constant_bytes;
  if (push_constant_bytes % 4 != 0 || push_constant_bytes > context.limits().maxPushConstantsSize)
    throw Error("vulkan: " + result.name + ": " + std::to_string(push_constant_bytes) + " bytes of push constants (" +
                context.info().name + " allows " + std::to_string(context.limits().maxPushConstantsSize) +
                ", multiple of 4)");

  VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module_info.codeSize = words.size_bytes();
  module_info.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  throwIfFailed(vkCreateShaderModule(context.device(), &module_info, nullptr, &module),
                "vkCreateShaderModule " + result.name);

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.pushConstantRangeCount = push_constant_bytes > 0 ? 1 : 0;
  layout_info.pPushConstantRanges = &range;
  VkResult r = vkCreatePipelineLayout(context.device(), &layout_info, nullptr, &result.layout);
  if (r != VK_SUCCESS) {
    vkDestroyShaderModule(context.device(), module, nullptr);
    throwIfFailed(r, "vkCreatePipelineLayout " + result.name);
  }

  std::vector<VkSpecializationMapEntry> entries;
  std::vector<uint32_t> values(specialization.begin(), specialization.end());
  for (uint32_t i = 0; i < specialization.size(); ++i) entries.push_back({i, 4 * i, 4});
  if (local) {
    for (const auto& [id, value] : {std::pair{uint32_t(WORKGROUP_SIZE_X_ID), local->x},
                                    std::pair{uint32_t(WORKGROUP_SIZE_Y_ID), local->y},
                                    std::pair{uint32_t(WORKGROUP_SIZE_Z_ID), local->z}}) {
      entries.push_back({id, uint32_t(4 * values.size()), 4});
      values.push_back(value);
    }
  }
  VkSpecializationInfo spec{uint32_t(entries.size()), entries.data(), values.size() * sizeof(uint32_t), values.data()};
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = entries.empty() ? nullptr : &spec;
  info.layout = result.layout;
  r = vkCreateComputePipelines(context.device(), VK_NULL_HANDLE, 1, &info, nullptr, &result.pipeline);
  // The module is only needed while the pipeline is created.
  vkDestroyShaderModule(context.device(), module, nullptr);
  if (r != VK_SUCCESS) {
    destroyComputePipeline(context, result);
    throwIfFailed(r, "vkCreateComputePipelines " + std::string(shader));
  }
  return result;
}

}  // namespace

ComputePipeline createComputePipeline(const VulkanContext& context, std::string_view shader,
                                      uint32_t push_constant_bytes, std::span<const uint32_t> specialization) {
  return createPipeline(context, shader, push_constant_bytes, specialization, nullptr);
}

ComputePipeline createComputePipeline(const VulkanContext& context, std::string_view shader,
                                      uint32_t push_constant_bytes, WorkgroupSize local,
                                      std::span<const uint32_t> specialization) {
  return createPipeline(context, shader, push_constant_bytes, specialization, &local);
}

void destroyComputePipeline(const VulkanContext& context, ComputePipeline& pipeline) {
  if (pipeline.pipeline != VK_NULL_HANDLE) vkDestroyPipeline(context.device(), pipeline.pipeline, nullptr);
  if (pipeline.layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(context.device(), pipeline.layout, nullptr);
  pipeline = ComputePipeline{};
}

namespace {

void bindAndPush(VkCommandBuffer cmd, const ComputePipeline& pipeline, const void* push, uint32_t push_bytes) {
  if (push_bytes != pipeline.push_constant_bytes) {
    // A C++ struct that disagrees with the shader's block: a bug, found the
    // first time the pass runs.
    std::fprintf(stderr, "fibscope: fatal: %s: %u bytes of push constants pushed, the pipeline has %u\n",
                 pipeline.name.c_str(), push_bytes, pipeline.push_constant_bytes);
    std::abort();
  }
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
  if (push_bytes > 0) vkCmdPushConstants(cmd, pipeline.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes, push);
}

}  // namespace

void recordDispatch(VkCommandBuffer cmd, const ComputePipeline& pipeline, const void* push, uint32_t push_bytes,
                    uint32_t groups_x, uint32_t groups_y, uint32_t groups_z) {
  bindAndPush(cmd, pipeline, push, push_bytes);
  vkCmdDispatch(cmd, groups_x, groups_y, groups_z);
}

void recordDispatchIndirect(VkCommandBuffer cmd, const ComputePipeline& pipeline, const void* push, uint32_t push_bytes,
                            VkBuffer indirect, VkDeviceSize offset) {
  bindAndPush(cmd, pipeline, push, push_bytes);
  vkCmdDispatchIndirect(cmd, indirect, offset);
}

DispatchGrid dispatchGrid(const VulkanContext& context, uint64_t count) {
  const uint64_t max_x = context.limits().maxComputeWorkGroupCount[0];
  const uint64_t max_y = context.limits().maxComputeWorkGroupCount[1];
  if (count == 0) return {0, 1};
  if (count <= max_x) return {uint32_t(count), 1};
  const uint64_t y = (count + max_x - 1) / max_x;
  if (y > max_y)
    throw Error("vulkan: " + std::to_string(count) + " workgroups exceed the dispatch limits of " +
                context.info().name);
  return {uint32_t(max_x), uint32_t(y)};
}

}  // namespace fibscope::gpu
