#include "gpu/vk_check.h"

#include <cstdio>
#include <cstdlib>

#include "core/error.h"

namespace fibscope::gpu {

const char* vkResultName(VkResult result) {
  switch (result) {
#define FIBSCOPE_VK_RESULT(name) \
  case name:                     \
    return #name;
    FIBSCOPE_VK_RESULT(VK_SUCCESS)
    FIBSCOPE_VK_RESULT(VK_NOT_READY)
    FIBSCOPE_VK_RESULT(VK_TIMEOUT)
    FIBSCOPE_VK_RESULT(VK_EVENT_SET)
    FIBSCOPE_VK_RESULT(VK_EVENT_RESET)
    FIBSCOPE_VK_RESULT(VK_INCOMPLETE)
    FIBSCOPE_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    FIBSCOPE_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    FIBSCOPE_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    FIBSCOPE_VK_RESULT(VK_ERROR_DEVICE_LOST)
    FIBSCOPE_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    FIBSCOPE_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    FIBSCOPE_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    FIBSCOPE_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    FIBSCOPE_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    FIBSCOPE_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    FIBSCOPE_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    FIBSCOPE_VK_RESULT(VK_ERROR_FRAGMENTED_POOL)
    FIBSCOPE_VK_RESULT(VK_ERROR_UNKNOWN)
    FIBSCOPE_VK_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
    FIBSCOPE_VK_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    FIBSCOPE_VK_RESULT(VK_ERROR_FRAGMENTATION)
    FIBSCOPE_VK_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    FIBSCOPE_VK_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
    FIBSCOPE_VK_RESULT(VK_ERROR_SURFACE_LOST_KHR)
    FIBSCOPE_VK_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    FIBSCOPE_VK_RESULT(VK_SUBOPTIMAL_KHR)
    FIBSCOPE_VK_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
    FIBSCOPE_VK_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
#undef FIBSCOPE_VK_RESULT
    default:
      break;
  }
  static thread_local char unknown[32];
  std::snprintf(unknown, sizeof unknown, "VkResult %d", int(result));
  return unknown;
}

void vkCheckFailed(const char* call, VkResult result, const char* file, int line) {
  std::fprintf(stderr, "fibscope: fatal: %s:%d: %s returned %s\n", file, line, call, vkResultName(result));
  std::fflush(stderr);
  std::abort();
}

void throwIfFailed(VkResult result, const std::string& what) {
  if (result != VK_SUCCESS) throw Error("vulkan: " + what + ": " + vkResultName(result));
}

}  // namespace fibscope::gpu
