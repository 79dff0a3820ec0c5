#include "gpu/image.h"

#include <utility>

#include "gpu/buffer.h"
#include "gpu/submit.h"
#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

bool isDepth(VkFormat format) {
  switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
      return true;
    default:
      return false;
  }
}

}  // namespace

Image createImage2D(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
                    VkImageUsageFlags usage) {
  const uint32_t max_side = context.limits().maxImageDimension2D;
  if (width == 0 || height == 0 || width > max_side || height > max_side)
    throw Error("vulkan: image of " + std::to_string(width) + " x " + std::to_string(height) + " pixels (1 to " +
                std::to_string(max_side) + " per side on " + context.info().name + ")");
  VkImageFormatProperties format_properties;
  if (vkGetPhysicalDeviceImageFormatProperties(context.physicalDevice(), format, VK_IMAGE_TYPE_2D,
                                               VK_IMAGE_TILING_OPTIMAL, usage, 0, &format_properties) != VK_SUCCESS)
    throw Error("vulkan: " + context.info().name + " has no 2D images of format " + std::to_string(int(format)) +
                " with usage 0x" + std::to_string(usage));
  Image image;
  image.format = format;
  image.extent = {width, height};
  image.aspect = isDepth(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  throwIfFailed(vkCreateImage(context.device(), &info, nullptr, &image.image), "vkCreateImage");
  try {
    VkMemoryRequirements requirements;
    vkGetImageMemoryRequirements(context.device(), image.image, &requirements);
    image.memory = allocateMemory(context, requirements, MemoryUse::DeviceLocal, false);
    VK_CHECK(vkBindImageMemory(context.device(), image.image, image.memory, 0));
    // A view only for usages that read or write through one.
    constexpr VkImageUsageFlags kViewUsages =
        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
    if (!(usage & kViewUsages)) return image;
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = image.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {image.aspect, 0, 1, 0, 1};
    throwIfFailed(vkCreateImageView(context.device(), &view, nullptr, &image.view), "vkCreateImageView");
  } catch (...) {
    destroyImage(context, image);
    throw;
  }
  return image;
}

void destroyImage(const VulkanContext& context, Image& image) {
  if (image.view != VK_NULL_HANDLE) vkDestroyImageView(context.device(), image.view, nullptr);
  if (image.image != VK_NULL_HANDLE) vkDestroyImage(context.device(), image.image, nullptr);
  if (image.memory != VK_NULL_HANDLE) vkFreeMemory(context.device(), image.memory, nullptr);
  image = Image{};
}

void transitionImage(VkCommandBuffer cmd, Image& image, VkImageLayout layout, VkPipelineStageFlags2 src_stage,
                     VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) {
  VkImageMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  barrier.srcStageMask = src_stage;
  barrier.srcAccessMask = src_access;
  barrier.dstStageMask = dst_stage;
  barrier.dstAccessMask = dst_access;
  barrier.oldLayout = image.layout;
  barrier.newLayout = layout;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image.image;
  barrier.subresourceRange = {image.aspect, 0, 1, 0, 1};
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.imageMemoryBarrierCount = 1;
  dependency.pImageMemoryBarriers = &barrier;
  vkCmdPipelineBarrier2(cmd, &dependency);
  image.layout = layout;
}

std::vector<uint8_t> downloadImageRgba8(const VulkanContext& context, Image& image) {
  bool swap_red_blue = false;
  switch (image.format) {
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
      break;
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
      swap_red_blue = true;
      break;
    default:
      throw Error("vulkan: downloadImageRgba8 needs an 8-bit RGBA or BGRA image, not format " +
                  std::to_string(int(image.format)));
  }
  const size_t bytes = size_t(image.extent.width) * image.extent.height * 4;
  Buffer staging = createBuffer(context, bytes, MemoryUse::Readback);
  std::vector<uint8_t> pixels(bytes);
  try {
    submitOnce(context, [&](VkCommandBuffer cmd) {
      transitionImage(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                      VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {image.extent.width, image.extent.height, 1};
      vkCmdCopyImageToBuffer(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.buffer, 1, &region);
      memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                    VK_ACCESS_2_HOST_READ_BIT);
    });
    downloadFromBuffer(context, staging, pixels.data(), bytes);
  } catch (...) {
    destroyBuffer(context, staging);
    throw;
  }
  destroyBuffer(context, staging);
  if (swap_red_blue)
    for (size_t i = 0; i < bytes; i += 4) std::swap(pixels[i], pixels[i + 2]);
  return pixels;
}

}  // namespace fibscope::gpu
