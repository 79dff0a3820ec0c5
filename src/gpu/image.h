// 2D images with one view, layout transitions, and read-back to host RGBA8
// (for image tests and PNG output).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  // none for transfer-only images
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  // The layout after the commands recorded so far (recording order is
  // submission order for the one-shot helpers that use it).
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

// A device-local 2D image of one mip level and layer, optimal tiling, with a
// view of the whole image when `usage` reads or writes through views. Throws Error when the format does not support
// `usage` or memory runs out.
Image createImage2D(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
                    VkImageUsageFlags usage);
void destroyImage(const VulkanContext& context, Image& image);

// Records a barrier that moves `image` to `layout`, after the given stages
// and accesses and before the next ones, and updates image.layout.
void transitionImage(VkCommandBuffer cmd, Image& image, VkImageLayout layout, VkPipelineStageFlags2 src_stage,
                     VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access);

// Copies an R8G8B8A8 or B8G8R8A8 (UNORM or SRGB) image created with
// TRANSFER_SRC usage into width * height * 4 bytes, rows top to bottom, RGBA
// order. Waits for the queue; leaves the image in TRANSFER_SRC_OPTIMAL.
std::vector<uint8_t> downloadImageRgba8(const VulkanContext& context, Image& image);

}  // namespace fibscope::gpu
