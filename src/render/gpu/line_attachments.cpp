#include "render/gpu/line_attachments.h"

#include "gpu/graphics_pipeline.h"
#include "gpu/submit.h"
#include "shared/render_config.h"

namespace fibscope {

void releaseLineAttachments(const gpu::VulkanContext& context, LineAttachments& a) {
  gpu::destroyImage(context, a.depth);
  gpu::destroyImage(context, a.color);
}

void ensureLineAttachments(const gpu::VulkanContext& context, LineAttachments& a, uint32_t width, uint32_t height) {
  if (a.color.image != VK_NULL_HANDLE && a.color.extent.width == width && a.color.extent.height == height) return;
  if (a.color.image != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(context.device());
    releaseLineAttachments(context, a);
  }
  try {
    a.color = gpu::createImage2D(context, width, height, kLineColorFormat,
                                 VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    a.depth = gpu::createImage2D(context, width, height, kLineDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  } catch (...) {
    releaseLineAttachments(context, a);
    throw;
  }
}

void beginLineAttachments(VkCommandBuffer cmd, LineAttachments& a) {
  // The previous frame's copy read the colour attachment: finish it before
  // the clear overwrites it (write-after-read, an execution dependency).
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0);
  // The empty texel: depth 1.0, no fiber, segment and tangent 0.
  VkClearColorValue clear{};
  clear.uint32[0] = 0x3F800000u;  // floatBitsToUint(1.0f)
  clear.uint32[1] = shader::kNoFiberId;
  gpu::beginRendering(cmd, a.color, clear, &a.depth, 1.0f);
}

void resumeLineAttachments(VkCommandBuffer cmd, LineAttachments& a) {
  // The copy out of the colour attachment before rendering writes it again;
  // the depth writes before the next depth tests.
  gpu::transitionImage(cmd, a.color, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
  constexpr VkPipelineStageFlags2 kDepthStages =
      VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
  gpu::memoryBarrier(cmd, kDepthStages, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, kDepthStages,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color.imageView = a.color.view;
  color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  depth.imageView = a.depth.view;
  depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  depth.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
  info.renderArea = {{0, 0}, a.color.extent};
  info.layerCount = 1;
  info.colorAttachmentCount = 1;
  info.pColorAttachments = &color;
  info.pDepthAttachment = &depth;
  vkCmdBeginRendering(cmd, &info);
  const VkViewport viewport{0, 0, float(a.color.extent.width), float(a.color.extent.height), 0, 1};
  const VkRect2D scissor{{0, 0}, a.color.extent};
  vkCmdSetViewport(cmd, 0, 1, &viewport);
  vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void endLineAttachmentsIntoGBuffer(VkCommandBuffer cmd, LineAttachments& a, const GpuFrameTargets& frame) {
  gpu::endRendering(cmd);
  gpu::transitionImage(cmd, a.color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  // Texel rows are tightly packed in the G-buffer: 16 bytes each, the
  // attachment's texel size.
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {frame.width, frame.height, 1};
  vkCmdCopyImageToBuffer(cmd, a.color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, frame.gbuffer.buffer, 1, &region);
}

}  // namespace fibscope
