#include "app/viewer/presentation.h"

#include "gpu/submit.h"
#include "gpu/vk_check.h"

namespace fibscope {
namespace {

constexpr VkFormat kPresentationFormat = VK_FORMAT_R8G8B8A8_UNORM;

VkRenderPass createUiRenderPass(const gpu::VulkanContext& context) {
  VkAttachmentDescription attachment{};
  attachment.format = kPresentationFormat;
  attachment.samples = VK_SAMPLE_COUNT_1_BIT;
  attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;  // the scene is already there
  attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachment.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachment.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachment.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  attachment.finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  VkAttachmentReference reference{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &reference;
  // In: the copy's writes were made available by the barrier before the
  // pass; out: the blit or read-back reads what the pass wrote (after the
  // final layout transition).
  VkSubpassDependency dependencies[2]{};
  dependencies[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  dependencies[0].dstSubpass = 0;
  dependencies[0].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dependencies[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dependencies[0].srcAccessMask = 0;
  dependencies[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  dependencies[1].srcSubpass = 0;
  dependencies[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  dependencies[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dependencies[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dependencies[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  dependencies[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 1;
  info.pAttachments = &attachment;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 2;
  info.pDependencies = dependencies;
  VkRenderPass pass = VK_NULL_HANDLE;
  gpu::throwIfFailed(vkCreateRenderPass(context.device(), &info, nullptr, &pass), "vkCreateRenderPass (UI)");
  return pass;
}

void createSized(const gpu::VulkanContext& context, Presentation& p, uint32_t width, uint32_t height) {
  p.image = gpu::createImage2D(context, width, height, kPresentationFormat,
                               VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                   VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  p.width = width;
  p.height = height;
  VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  info.renderPass = p.render_pass;
  info.attachmentCount = 1;
  info.pAttachments = &p.image.view;
  info.width = width;
  info.height = height;
  info.layers = 1;
  gpu::throwIfFailed(vkCreateFramebuffer(context.device(), &info, nullptr, &p.framebuffer), "vkCreateFramebuffer");
}

void destroySized(const gpu::VulkanContext& context, Presentation& p) {
  if (p.framebuffer != VK_NULL_HANDLE) vkDestroyFramebuffer(context.device(), p.framebuffer, nullptr);
  p.framebuffer = VK_NULL_HANDLE;
  gpu::destroyImage(context, p.image);
  p.width = p.height = 0;
}

}  // namespace

Presentation createPresentation(const gpu::VulkanContext& context, uint32_t width, uint32_t height) {
  Presentation p;
  try {
    p.render_pass = createUiRenderPass(context);
    createSized(context, p, width, height);
  } catch (...) {
    destroyPresentation(context, p);
    throw;
  }
  return p;
}

void resizePresentation(const gpu::VulkanContext& context, Presentation& p, uint32_t width, uint32_t height) {
  if (width == p.width && height == p.height) return;
  vkDeviceWaitIdle(context.device());
  destroySized(context, p);
  createSized(context, p, width, height);
}

void destroyPresentation(const gpu::VulkanContext& context, Presentation& p) {
  destroySized(context, p);
  if (p.render_pass != VK_NULL_HANDLE) vkDestroyRenderPass(context.device(), p.render_pass, nullptr);
  p.render_pass = VK_NULL_HANDLE;
}

void recordCopyColorToPresentation(VkCommandBuffer cmd, const gpu::Buffer& color, Presentation& p) {
  // The shade pass wrote the colour buffer from a compute shader.
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  // The whole image is overwritten: its old contents (last frame's blit
  // source) need not be kept, only the blit's read must be done.
  p.image.layout = VK_IMAGE_LAYOUT_UNDEFINED;
  gpu::transitionImage(cmd, p.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0,
                       VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {p.width, p.height, 1};
  vkCmdCopyBufferToImage(cmd, color.buffer, p.image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  gpu::transitionImage(cmd, p.image, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
}

void beginPresentationPass(VkCommandBuffer cmd, const Presentation& p) {
  VkRenderPassBeginInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  info.renderPass = p.render_pass;
  info.framebuffer = p.framebuffer;
  info.renderArea.extent = {p.width, p.height};
  vkCmdBeginRenderPass(cmd, &info, VK_SUBPASS_CONTENTS_INLINE);
}

void endPresentationPass(VkCommandBuffer cmd, Presentation& p) {
  vkCmdEndRenderPass(cmd);
  p.image.layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;  // the pass's final layout
}

void recordBlitToSwapchain(VkCommandBuffer cmd, const Presentation& p, VkImage swapchain_image, VkExtent2D extent) {
  // The swapchain image's old contents are not needed. Its acquire
  // semaphore is waited on at the transfer stage, so the layout transition
  // starts there too.
  VkImageMemoryBarrier2 to_dst{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  to_dst.srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
  to_dst.srcAccessMask = 0;
  to_dst.dstStageMask = VK_PIPELINE_STAGE_2_BLIT_BIT;
  to_dst.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  to_dst.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  to_dst.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  to_dst.srcQueueFamilyIndex = to_dst.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  to_dst.image = swapchain_image;
  to_dst.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = 1;
  dep.pImageMemoryBarriers = &to_dst;
  vkCmdPipelineBarrier2(cmd, &dep);

  VkImageBlit blit{};
  blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  blit.srcOffsets[1] = {int32_t(p.width), int32_t(p.height), 1};
  blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  blit.dstOffsets[1] = {int32_t(extent.width), int32_t(extent.height), 1};
  // Same size except during a resize: nearest keeps the pixels exact.
  vkCmdBlitImage(cmd, p.image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, swapchain_image,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);

  VkImageMemoryBarrier2 to_present = to_dst;
  to_present.srcStageMask = VK_PIPELINE_STAGE_2_BLIT_BIT;
  to_present.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  // Presentation is ordered by the semaphore the submission signals.
  to_present.dstStageMask = VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT;
  to_present.dstAccessMask = 0;
  to_present.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  to_present.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  dep.pImageMemoryBarriers = &to_present;
  vkCmdPipelineBarrier2(cmd, &dep);
}

std::vector<uint8_t> downloadPresentation(const gpu::VulkanContext& context, Presentation& p) {
  return gpu::downloadImageRgba8(context, p.image);
}

}  // namespace fibscope
