// Graphics pipelines from embedded SPIR-V with dynamic rendering (Vulkan
// 1.3: no render pass or framebuffer objects). Like the compute passes, the
// vertex shader pulls its data through buffer references in push constants,
// so there is no vertex input state and no descriptor set.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <string_view>

#include "gpu/image.h"
#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

struct GraphicsPipelineDesc {
  std::string_view vertex_shader;    // e.g. "lines.vert"
  std::string_view fragment_shader;  // e.g. "lines.frag"
  // Optional stages (empty: none): a geometry shader (needs the device's
  // geometryShader feature), a tessellation control + evaluation pair
  // (tessellationShader; topology PATCH_LIST with patch_control_points).
  std::string_view geometry_shader;
  std::string_view tess_control_shader;
  std::string_view tess_evaluation_shader;
  uint32_t patch_control_points = 0;
  // A mesh pipeline (VK_EXT_mesh_shader enabled on the device:
  // VulkanContext::meshShader): an optional task shader and a mesh shader
  // instead of the vertex shader (vertex_shader empty; no vertex input or
  // input assembly; the topology is the mesh shader's).
  std::string_view task_shader;
  std::string_view mesh_shader;
  VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkFormat color_format = VK_FORMAT_R8G8B8A8_UNORM;  // UNDEFINED: no colour attachment
  VkFormat depth_format = VK_FORMAT_UNDEFINED;       // UNDEFINED: no depth test
  bool primitive_restart = false;                    // strips: index 0xffffffff ends one
  uint32_t push_constant_bytes = 0;                  // visible to every stage of the pipeline
  // The line width is dynamic state (vkCmdSetLineWidth before drawing;
  // widths other than 1 need the wideLines feature).
  bool dynamic_line_width = false;
  // Rasterisation samples (multisampling; without attachments the device's
  // framebufferNoAttachmentsSampleCounts says which are allowed).
  VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
};

struct GraphicsPipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  uint32_t push_constant_bytes = 0;
  VkShaderStageFlags stages = 0;  // the pipeline's stages: the push constants' range
  std::string name;               // "vertex + fragment", for messages
};

// Viewport and scissor are dynamic state (set by beginRendering). Throws
// Error when a shader is unknown, the push constants are too large or the
// driver rejects the pipeline.
GraphicsPipeline createGraphicsPipeline(const VulkanContext& context, const GraphicsPipelineDesc& desc);
void destroyGraphicsPipeline(const VulkanContext& context, GraphicsPipeline& pipeline);

// Moves `color` (and `depth` when given) to attachment layouts, begins
// dynamic rendering over the whole colour image with these clear values and
// sets the viewport and scissor to it. The previous contents are discarded.
void beginRendering(VkCommandBuffer cmd, Image& color, const VkClearColorValue& clear_color, Image* depth = nullptr,
                    float clear_depth = 1.0f);
// Dynamic rendering of a width x height area without attachments, for
// passes whose fragment shaders only write storage buffers (the pipeline's
// color_format and depth_format UNDEFINED); sets the viewport and scissor.
void beginRenderingWithoutAttachments(VkCommandBuffer cmd, uint32_t width, uint32_t height);
void endRendering(VkCommandBuffer cmd);

// Binds the pipeline, pushes `push` (its size must be the pipeline's; a
// mismatch aborts) and draws `vertex_count` vertices without vertex buffers.
void recordDraw(VkCommandBuffer cmd, const GraphicsPipeline& pipeline, const void* push, uint32_t push_bytes,
                uint32_t vertex_count, uint32_t instance_count = 1);
template <typename PushConstants>
void recordDraw(VkCommandBuffer cmd, const GraphicsPipeline& pipeline, const PushConstants& push, uint32_t vertex_count,
                uint32_t instance_count = 1) {
  recordDraw(cmd, pipeline, &push, uint32_t(sizeof(PushConstants)), vertex_count, instance_count);
}

}  // namespace fibscope::gpu
