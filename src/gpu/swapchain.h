// The window's swapchain: images the frame is blitted into and presented
// from, on the context's one queue. Plain struct + free functions (STYLE.md
// rule 4); the owner recreates it when the window is resized or when
// acquire/present report VK_ERROR_OUT_OF_DATE_KHR or VK_SUBOPTIMAL_KHR.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

struct SwapchainOptions {
  // FIFO (vsync, always available) when true; else MAILBOX, then IMMEDIATE
  // where the surface offers them, FIFO otherwise.
  bool vsync = true;
};

struct Swapchain {
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  // B8G8R8A8_UNORM where offered: the frame's colour buffer already holds
  // display-ready (sRGB-encoded) bytes, so an _SRGB format would encode
  // them a second time.
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkColorSpaceKHR color_space = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  VkPresentModeKHR present_mode = VK_PRESENT_MODE_FIFO_KHR;
  VkExtent2D extent{0, 0};
  std::vector<VkImage> images;  // usage: COLOR_ATTACHMENT | TRANSFER_DST
  // One frame in flight: acquire signals `acquired`, the frame's submission
  // waits on it and signals rendered[image], present waits on that. One
  // `rendered` per image: a presentation has no fence, so a semaphore it
  // waits on is only known to be free again once its image is acquired anew.
  VkSemaphore acquired = VK_NULL_HANDLE;
  std::vector<VkSemaphore> rendered;
  SwapchainOptions options;
};

// A swapchain for the context's surface, `width` x `height` clamped to what
// the surface allows (the surface's current extent when it dictates one).
// `old` (may be null) is handed to the driver as oldSwapchain and destroyed.
// Throws Error when the surface offers no usable format or creation fails.
// A zero-sized surface (a minimised window) gives extent 0 x 0 and no
// swapchain: the caller skips frames until the window has a size again.
Swapchain createSwapchain(const VulkanContext& context, uint32_t width, uint32_t height,
                          const SwapchainOptions& options, Swapchain* old = nullptr);
// Waits for the device to be idle, then destroys everything.
void destroySwapchain(const VulkanContext& context, Swapchain& swapchain);
// Recreates in place for a new window size (waits for the device).
void recreateSwapchain(const VulkanContext& context, Swapchain& swapchain, uint32_t width, uint32_t height);

enum class SwapchainStatus : uint8_t {
  Ok,
  OutOfDate,  // recreate and try again (the frame is skipped)
};

// Acquires the next image (signals swapchain.acquired). Suboptimal still
// returns Ok with the image (present then reports OutOfDate so the caller
// recreates after the frame). Throws Error when the surface is lost.
SwapchainStatus acquireSwapchainImage(const VulkanContext& context, Swapchain& swapchain, uint32_t& image_index);
// Presents image_index after swapchain.rendered[image_index]. OutOfDate for
// VK_ERROR_OUT_OF_DATE_KHR and VK_SUBOPTIMAL_KHR.
SwapchainStatus presentSwapchainImage(const VulkanContext& context, Swapchain& swapchain, uint32_t image_index);

const char* presentModeName(VkPresentModeKHR mode);

}  // namespace fibscope::gpu
