#include "gpu/swapchain.h"

#include <algorithm>

#include "core/error.h"
#include "gpu/vk_check.h"

namespace fibscope::gpu {
namespace {

VkSurfaceFormatKHR chooseFormat(const VulkanContext& context) {
  uint32_t count = 0;
  throwIfFailed(vkGetPhysicalDeviceSurfaceFormatsKHR(context.physicalDevice(), context.surface(), &count, nullptr),
                "vkGetPhysicalDeviceSurfaceFormatsKHR");
  std::vector<VkSurfaceFormatKHR> formats(count);
  throwIfFailed(
      vkGetPhysicalDeviceSurfaceFormatsKHR(context.physicalDevice(), context.surface(), &count, formats.data()),
      "vkGetPhysicalDeviceSurfaceFormatsKHR");
  // UNORM only: the frame's bytes are already sRGB-encoded.
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == wanted && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
  // A surface with no preference.
  if (count == 1 && formats[0].format == VK_FORMAT_UNDEFINED)
    return {VK_FORMAT_B8G8R8A8_UNORM, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
  throw Error("vulkan: the window surface offers no B8G8R8A8_UNORM or R8G8B8A8_UNORM format");
}

VkPresentModeKHR choosePresentMode(const VulkanContext& context, bool vsync) {
  if (vsync) return VK_PRESENT_MODE_FIFO_KHR;  // the one mode every surface has
  uint32_t count = 0;
  vkGetPhysicalDeviceSurfacePresentModesKHR(context.physicalDevice(), context.surface(), &count, nullptr);
  std::vector<VkPresentModeKHR> modes(count);
  vkGetPhysicalDeviceSurfacePresentModesKHR(context.physicalDevice(), context.surface(), &count, modes.data());
  for (VkPresentModeKHR wanted : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR})
    if (std::find(modes.begin(), modes.end(), wanted) != modes.end()) return wanted;
  return VK_PRESENT_MODE_FIFO_KHR;
}

VkSemaphore createSemaphore(const VulkanContext& context) {
  VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  VkSemaphore semaphore = VK_NULL_HANDLE;
  throwIfFailed(vkCreateSemaphore(context.device(), &info, nullptr, &semaphore), "vkCreateSemaphore");
  return semaphore;
}

void destroySemaphores(const VulkanContext& context, Swapchain& swapchain) {
  if (swapchain.acquired != VK_NULL_HANDLE) vkDestroySemaphore(context.device(), swapchain.acquired, nullptr);
  swapchain.acquired = VK_NULL_HANDLE;
  for (VkSemaphore s : swapchain.rendered) vkDestroySemaphore(context.device(), s, nullptr);
  swapchain.rendered.clear();
}

}  // namespace

const char* presentModeName(VkPresentModeKHR mode) {
  switch (mode) {
    case VK_PRESENT_MODE_FIFO_KHR:
      return "fifo";
    case VK_PRESENT_MODE_FIFO_RELAXED_KHR:
      return "fifo-relaxed";
    case VK_PRESENT_MODE_MAILBOX_KHR:
      return "mailbox";
    case VK_PRESENT_MODE_IMMEDIATE_KHR:
      return "immediate";
    default:
      return "other";
  }
}

Swapchain createSwapchain(const VulkanContext& context, uint32_t width, uint32_t height,
                          const SwapchainOptions& options, Swapchain* old) {
  if (context.surface() == VK_NULL_HANDLE) throw Error("vulkan: a swapchain needs a context with a window surface");
  Swapchain result;
  result.options = options;
  VkSwapchainKHR old_handle = old ? old->swapchain : VK_NULL_HANDLE;
  try {
    VkSurfaceCapabilitiesKHR caps;
    throwIfFailed(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(context.physicalDevice(), context.surface(), &caps),
                  "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
    // 0xFFFFFFFF: the surface takes its size from the swapchain.
    if (caps.currentExtent.width != 0xFFFFFFFFu) {
      result.extent = caps.currentExtent;
    } else {
      result.extent.width = std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width);
      result.extent.height = std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height);
    }
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
      throw Error("vulkan: the window surface cannot be a transfer destination (the frame is blitted into it)");
    const VkSurfaceFormatKHR format = chooseFormat(context);
    result.format = format.format;
    result.color_space = format.colorSpace;
    result.present_mode = choosePresentMode(context, options.vsync);

    if (result.extent.width > 0 && result.extent.height > 0) {
      // One more than the minimum so that acquire rarely waits on the
      // presentation engine.
      uint32_t image_count = caps.minImageCount + 1;
      if (caps.maxImageCount > 0) image_count = std::min(image_count, caps.maxImageCount);
      VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
      info.surface = context.surface();
      info.minImageCount = image_count;
      info.imageFormat = result.format;
      info.imageColorSpace = result.color_space;
      info.imageExtent = result.extent;
      info.imageArrayLayers = 1;
      info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                        (caps.supportedUsageFlags & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
      info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;  // one queue does everything
      info.preTransform = (caps.supportedTransforms & VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR)
                              ? VK_SURFACE_TRANSFORM_IDENTITY_BIT_KHR
                              : caps.currentTransform;
      info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
      for (VkCompositeAlphaFlagBitsKHR a : {VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR, VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR,
                                            VK_COMPOSITE_ALPHA_PRE_MULTIPLIED_BIT_KHR,
                                            VK_COMPOSITE_ALPHA_POST_MULTIPLIED_BIT_KHR})
        if (caps.supportedCompositeAlpha & a) {
          info.compositeAlpha = a;
          break;
        }
      info.presentMode = result.present_mode;
      info.clipped = VK_TRUE;
      info.oldSwapchain = old_handle;
      throwIfFailed(vkCreateSwapchainKHR(context.device(), &info, nullptr, &result.swapchain),
                    "vkCreateSwapchainKHR");
      uint32_t count = 0;
      throwIfFailed(vkGetSwapchainImagesKHR(context.device(), result.swapchain, &count, nullptr),
                    "vkGetSwapchainImagesKHR");
      result.images.resize(count);
      throwIfFailed(vkGetSwapchainImagesKHR(context.device(), result.swapchain, &count, result.images.data()),
                    "vkGetSwapchainImagesKHR");
      result.acquired = createSemaphore(context);
      for (uint32_t i = 0; i < count; ++i) result.rendered.push_back(createSemaphore(context));
    }
  } catch (...) {
    destroySwapchain(context, result);
    if (old) destroySwapchain(context, *old);
    throw;
  }
  if (old) destroySwapchain(context, *old);
  return result;
}

void destroySwapchain(const VulkanContext& context, Swapchain& swapchain) {
  vkDeviceWaitIdle(context.device());
  destroySemaphores(context, swapchain);
  if (swapchain.swapchain != VK_NULL_HANDLE) vkDestroySwapchainKHR(context.device(), swapchain.swapchain, nullptr);
  swapchain.swapchain = VK_NULL_HANDLE;
  swapchain.images.clear();
  swapchain.extent = {0, 0};
}

void recreateSwapchain(const VulkanContext& context, Swapchain& swapchain, uint32_t width, uint32_t height) {
  vkDeviceWaitIdle(context.device());
  Swapchain old = swapchain;
  swapchain = {};
  swapchain = createSwapchain(context, width, height, old.options, &old);
}

SwapchainStatus acquireSwapchainImage(const VulkanContext& context, Swapchain& swapchain, uint32_t& image_index) {
  if (swapchain.swapchain == VK_NULL_HANDLE) return SwapchainStatus::OutOfDate;
  const VkResult r = vkAcquireNextImageKHR(context.device(), swapchain.swapchain, UINT64_MAX, swapchain.acquired,
                                           VK_NULL_HANDLE, &image_index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) return SwapchainStatus::OutOfDate;
  if (r == VK_SUBOPTIMAL_KHR) return SwapchainStatus::Ok;
  throwIfFailed(r, "vkAcquireNextImageKHR");
  return SwapchainStatus::Ok;
}

SwapchainStatus presentSwapchainImage(const VulkanContext& context, Swapchain& swapchain, uint32_t image_index) {
  VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  info.waitSemaphoreCount = 1;
  info.pWaitSemaphores = &swapchain.rendered[image_index];
  info.swapchainCount = 1;
  info.pSwapchains = &swapchain.swapchain;
  info.pImageIndices = &image_index;
  const VkResult r = vkQueuePresentKHR(context.queue(), &info);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) return SwapchainStatus::OutOfDate;
  throwIfFailed(r, "vkQueuePresentKHR");
  return SwapchainStatus::Ok;
}

}  // namespace fibscope::gpu
