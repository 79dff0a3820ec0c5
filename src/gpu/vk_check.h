// Checking Vulkan results.
//
// VK_CHECK is for calls whose failure means a bug or a broken device (a
// wrong handle, device loss in the middle of recording): it prints the call,
// the VkResult name and file:line and aborts, in every build type. Failures a
// user can cause or fix (no driver, a missing feature, not enough memory)
// throw fibscope::Error with one line that starts "vulkan: " instead.
#pragma once

#include <vulkan/vulkan.h>

#include <string>

namespace fibscope::gpu {

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.; the number for unknown values.
const char* vkResultName(VkResult result);

[[noreturn]] void vkCheckFailed(const char* call, VkResult result, const char* file, int line);

// Throws Error("vulkan: WHAT: RESULT_NAME") when result is not VK_SUCCESS.
void throwIfFailed(VkResult result, const std::string& what);

}  // namespace fibscope::gpu

#define VK_CHECK(call)                                                                                               \
  do {                                                                                                               \
    const VkResult vk_check_result_ = (call);                                                                        \
    if (vk_check_result_ != VK_SUCCESS) ::fibscope::gpu::vkCheckFailed(#call, vk_check_result_, __FILE__, __LINE__); \
  } while (false)
