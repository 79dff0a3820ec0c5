#include "gpu/graphics_pipeline.h"

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "gpu/shader_library.h"
#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

VkShaderModule createModule(const VulkanContext& context, std::string_view name) {
  const std::span<const uint32_t> words = shaderWords(name);
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = words.size_bytes();
  info.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  throwIfFailed(vkCreateShaderModule(context.device(), &info, nullptr, &module),
                "vkCreateShaderModule " + std::string(name));
  return module;
}

}  // namespace

GraphicsPipeline createGraphicsPipeline(const VulkanContext& context, const GraphicsPipelineDesc& desc) {
  GraphicsPipeline result;
  result.name = std::string(desc.vertex_shader) + " + " + std::string(desc.fragment_shader);
  result.push_constant_bytes = desc.push_constant_bytes;
  if (desc.push_constant_bytes % 4 != 0 || desc.push_constant_bytes > context.limits().maxPushConstantsSize)
    throw Error("vulkan: " + result.name + ": " + std::to_string(desc.push_constant_bytes) +
                " bytes of push constants (" + context.info().name + " allows " +
                std::to_string(context.limits().maxPushConstantsSize) + ", multiple of 4)");

  // The stages in pipeline order (vertex, tessellation, geometry, fragment).
  struct Stage {
    VkShaderStageFlagBits stage;
    std::string_view shader;
  };
  const bool mesh = !desc.mesh_shader.empty();
  std::vector<Stage> wanted;
  if (mesh) {
    if (!context.meshShader().enabled)
      throw Error("vulkan: " + std::string(desc.mesh_shader) + ": VK_EXT_mesh_shader not supported by " +
                  context.info().name);
    if (!desc.task_shader.empty()) wanted.push_back({VK_SHADER_STAGE_TASK_BIT_EXT, desc.task_shader});
    wanted.push_back({VK_SHADER_STAGE_MESH_BIT_EXT, desc.mesh_shader});
  } else {
    wanted.push_back({VK_SHADER_STAGE_VERTEX_BIT, desc.vertex_shader});
  }
  if (!desc.tess_control_shader.empty()) {
    wanted.push_back({VK_SHADER_STAGE_TESSELLATION_CONTROL_BIT, desc.tess_control_shader});
    wanted.push_back({VK_SHADER_STAGE_TESSELLATION_EVALUATION_BIT, desc.tess_evaluation_shader});
  }
  if (!desc.geometry_shader.empty()) wanted.push_back({VK_SHADER_STAGE_GEOMETRY_BIT, desc.geometry_shader});
  wanted.push_back({VK_SHADER_STAGE_FRAGMENT_BIT, desc.fragment_shader});
  result.name.clear();
  for (const Stage& w : wanted) result.name += (result.name.empty() ? "" : " + ") + std::string(w.shader);
  for (const Stage& w : wanted) result.stages |= w.stage;

  std::vector<VkShaderModule> modules;
  auto destroyModules = [&] {
    for (VkShaderModule m : modules) vkDestroyShaderModule(context.device(), m, nullptr);
  };
  try {
    for (const Stage& w : wanted) modules.push_back(createModule(context, w.shader));
  } catch (...) {
    destroyModules();
    throw;
  }

  VkPushConstantRange range{result.stages, 0, desc.push_constant_bytes};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.pushConstantRangeCount = desc.push_constant_bytes > 0 ? 1 : 0;
  layout_info.pPushConstantRanges = &range;
  VkResult r = vkCreatePipelineLayout(context.device(), &layout_info, nullptr, &result.layout);

  if (r == VK_SUCCESS) {
    std::vector<VkPipelineShaderStageCreateInfo> stages(wanted.size());
    for (size_t i = 0; i < wanted.size(); ++i) {
      stages[i] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      stages[i].stage = wanted[i].stage;
      stages[i].module = modules[i];
      stages[i].pName = "main";
    }
    VkPipelineTessellationStateCreateInfo tessellation{VK_STRUCTURE_TYPE_PIPELINE_TESSELLATION_STATE_CREATE_INFO};
    tessellation.patchControlPoints = desc.patch_control_points;

    VkPipelineVertexInputStateCreateInfo vertex_input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = desc.topology;
    assembly.primitiveRestartEnable = desc.primitive_restart;
    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = desc.samples;
    VkPipelineDepthStencilStateCreateInfo depth{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = desc.depth_format != VK_FORMAT_UNDEFINED;
    depth.depthWriteEnable = depth.depthTestEnable;
    depth.depthCompareOp = VK_COMPARE_OP_LESS;
    VkPipelineColorBlendAttachmentState blend_attachment{};
    blend_attachment.colorWriteMask =
        VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    const bool has_color = desc.color_format != VK_FORMAT_UNDEFINED;
    blend.attachmentCount = has_color ? 1 : 0;
    blend.pAttachments = &blend_attachment;
    const VkDynamicState dynamic_states[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR,
                                             VK_DYNAMIC_STATE_LINE_WIDTH};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = desc.dynamic_line_width ? 3 : 2;
    dynamic.pDynamicStates = dynamic_states;
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = has_color ? 1 : 0;
    rendering.pColorAttachmentFormats = has_color ? &desc.color_format : nullptr;
    rendering.depthAttachmentFormat = desc.depth_format;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.pNext = &rendering;
    info.stageCount = uint32_t(stages.size());
    info.pStages = stages.data();
    info.pTessellationState = desc.tess_control_shader.empty() ? nullptr : &tessellation;
    info.pVertexInputState = mesh ? nullptr : &vertex_input;  // (mesh pipelines have neither)
    info.pInputAssemblyState = mesh ? nullptr : &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = result.layout;
    r = vkCreateGraphicsPipelines(context.device(), VK_NULL_HANDLE, 1, &info, nullptr, &result.pipeline);
  }
  destroyModules();
  if (r != VK_SUCCESS) {
    destroyGraphicsPipeline(context, result);
    throwIfFailed(r, "creating the graphics pipeline " + result.name);
  }
  return result;
}

void destroyGraphicsPipeline(const VulkanContext& context, GraphicsPipeline& pipeline) {
  if (pipeline.pipeline != VK_NULL_HANDLE) vkDestroyPipeline(context.device(), pipeline.pipeline, nullptr);
  if (pipeline.layout != VK_NULL_HANDLE) vkDestroyPipelineLayout(context.device(), pipeline.layout, nullptr);
  pipeline = GraphicsPipeline{};
}

void beginRendering(VkCommandBuffer cmd, Image& color, const VkClearColorValue& clear_color, Image* depth,
                    float clear_depth) {
  // From UNDEFINED (contents discarded): wait only for earlier accesses of
  // the same attachment kind (write-after-write).
  color.layout = VK_IMAGE_LAYOUT_UNDEFINED;
  transitionImage(cmd, color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                  0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
  VkRenderingAttachmentInfo color_attachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color_attachment.imageView = color.view;
  color_attachment.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color_attachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  color_attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color_attachment.clearValue.color = clear_color;
  VkRenderingAttachmentInfo depth_attachment{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  if (depth) {
    depth->layout = VK_IMAGE_LAYOUT_UNDEFINED;
    constexpr VkPipelineStageFlags2 kDepthStages =
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    transitionImage(cmd, *depth, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, kDepthStages, 0, kDepthStages,
                    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    depth_attachment.imageView = depth->view;
    depth_attachment.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth_attachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth_attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth_attachment.clearValue.depthStencil = {clear_depth, 0};
  }
  VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
  info.renderArea = {{0, 0}, color.extent};
  info.layerCount = 1;
  info.colorAttachmentCount = 1;
  info.pColorAttachments = &color_attachment;
  info.pDepthAttachment = depth ? &depth_attachment : nullptr;
  vkCmdBeginRendering(cmd, &info);
  const VkViewport viewport{0, 0, float(color.extent.width), float(color.extent.height), 0, 1};
  const VkRect2D scissor{{0, 0}, color.extent};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void beginRenderingWithoutAttachments(VkCommandBuffer cmd, uint32_t width, uint32_t height) {
  VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
  info.renderArea = {{0, 0}, {width, height}};
  info.layerCount = 1;
  vkCmdBeginRendering(cmd, &info);
  const VkViewport viewport{0, 0, float(width), float(height), 0, 1};
  const VkRect2D scissor{{0, 0}, {width, height}};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void endRendering(VkCommandBuffer cmd) { vkCmdEndRendering(cmd); }

void recordDraw(VkCommandBuffer cmd, const GraphicsPipeline& pipeline, const void* push, uint32_t push_bytes,
                uint32_t vertex_count, uint32_t instance_count) {
  if (push_bytes != pipeline.push_constant_bytes) {
    std::fprintf(stderr, "fibscope: fatal: %s: %u bytes of push constants pushed, the pipeline has %u\n",
                 pipeline.name.c_str(), push_bytes, pipeline.push_constant_bytes);
    std::abort();
  }
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.pipeline);
  if (push_bytes > 0) vkCmdPushConstants(cmd, pipeline.layout, pipeline.stages, 0, push_bytes, push);
  vkCmdDraw(cmd, vertex_count, instance_count, 0, 0);
}

}  // namespace fibscope::gpu
