// The presentation image: what the window shows, at the window's size. Each
// frame the renderer's RGBA8 colour buffer is copied into it, ImGui draws on
// top in a render pass that loads it (loadOp LOAD), and it is blitted to the
// swapchain image (or, offscreen, just kept). Screenshots "as shown" read it.
// Plain struct + free functions (STYLE.md rule 4).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/image.h"
#include "gpu/vulkan_context.h"

namespace fibscope {

struct Presentation {
  // R8G8B8A8_UNORM (the colour buffer's byte order; its bytes are already
  // display-ready), usage COLOR_ATTACHMENT | TRANSFER_SRC | TRANSFER_DST.
  gpu::Image image;
  // One colour attachment: initial COLOR_ATTACHMENT_OPTIMAL, loadOp LOAD,
  // final TRANSFER_SRC_OPTIMAL (blit or read-back next). Independent of the
  // size: kept across resizes (ImGui's pipeline is made for it).
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  uint32_t width = 0, height = 0;
};

// Throws Error when memory runs out.
Presentation createPresentation(const gpu::VulkanContext& context, uint32_t width, uint32_t height);
// New size: the image and framebuffer are made again (waits for the device).
void resizePresentation(const gpu::VulkanContext& context, Presentation& presentation, uint32_t width,
                        uint32_t height);
void destroyPresentation(const gpu::VulkanContext& context, Presentation& presentation);

// After the renderer's record(): waits for the shade pass's writes to
// `color` (width x height RGBA8, top row first), copies it into the image
// and leaves the image in COLOR_ATTACHMENT_OPTIMAL for the UI pass.
void recordCopyColorToPresentation(VkCommandBuffer cmd, const gpu::Buffer& color, Presentation& presentation);
// Begins / ends the UI render pass (the image ends in TRANSFER_SRC_OPTIMAL).
void beginPresentationPass(VkCommandBuffer cmd, const Presentation& presentation);
void endPresentationPass(VkCommandBuffer cmd, Presentation& presentation);
// Blits the image (TRANSFER_SRC_OPTIMAL) onto a swapchain image of
// `extent` (scaled when the sizes differ during a resize) and leaves that in
// PRESENT_SRC_KHR.
void recordBlitToSwapchain(VkCommandBuffer cmd, const Presentation& presentation, VkImage swapchain_image,
                           VkExtent2D extent);

// The image as shown (RGBA, top row first); waits for the queue.
std::vector<uint8_t> downloadPresentation(const gpu::VulkanContext& context, Presentation& presentation);

}  // namespace fibscope
