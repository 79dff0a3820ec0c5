// The Vulkan instance: loader version check, optional validation layers with
// a debug messenger that keeps what they report, and the list of physical
// devices with the facts fibscope chooses by.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/error.h"

namespace fibscope::gpu {

// Thrown when there is no usable Vulkan device at all (no driver, or no
// device with what fibscope needs): GPU tests skip on it, the command line
// reports it as one line.
class VulkanUnavailable : public Error {
 public:
  explicit VulkanUnavailable(const std::string& message) : Error(message) {}
};

// What the validation layers (and the loader) reported through
// VK_EXT_debug_utils. Thread-safe: drivers may call back from any thread.
class DebugLog {
 public:
  explicit DebugLog(bool echo = false) : echo_(echo) {}
  void add(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* message);
  int errors() const;
  int warnings() const;
  // "error: ..." / "warning: ..." lines in the order they came.
  std::vector<std::string> messages() const;
  // Forgets everything (a test that provoked an error on purpose).
  void clear();

 private:
  mutable std::mutex mutex_;
  bool echo_;  // also print each message to stderr as it comes
  int errors_ = 0;
  int warnings_ = 0;
  std::vector<std::string> messages_;
};

struct InstanceOptions {
  // VK_LAYER_KHRONOS_validation with synchronisation validation; Error (one
  // line naming the Debian package) when the layer is not installed.
  bool validation = false;
  // Where messages go; when null, a log that also prints them to stderr
  // with validation on (without it, only the loader reports, and a failure
  // it explains becomes the one-line Error).
  std::shared_ptr<DebugLog> log;
  // More instance extensions to enable, e.g. the surface extensions a window
  // system needs (glfwGetRequiredInstanceExtensions). Error naming the first
  // one the loader does not offer.
  std::vector<std::string> extensions;
};

struct DeviceInfo {
  uint32_t index = 0;  // in vkEnumeratePhysicalDevices order
  VkPhysicalDevice handle = VK_NULL_HANDLE;
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t api_version = 0;
  std::string driver_name;  // e.g. "llvmpipe", "NVIDIA"
  std::string driver_info;  // e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
  uint32_t subgroup_size = 0;
  // Compute shaders may use subgroupShuffleUp (KHR_shader_subgroup_shuffle_relative).
  bool subgroup_shuffle_relative = false;
  uint64_t max_storage_buffer_range = 0;
  uint32_t max_push_constants_size = 0;
  uint64_t max_memory_allocation_size = 0;
  uint32_t max_compute_workgroup_count[3] = {0, 0, 0};
  float timestamp_period_ns = 0;
  bool buffer_device_address = false;
  bool shader_int64 = false;
  bool buffer_int64_atomics = false;
  bool synchronization2 = false;
  bool mesh_shader = false;  // VK_EXT_mesh_shader
  // Queue family with compute (and graphics if any family has both); -1
  // when the device has no compute queue.
  int queue_family = -1;
  bool queue_has_graphics = false;
  uint32_t timestamp_valid_bits = 0;  // of that queue family
  // Empty when fibscope can use the device, else what it lacks, e.g.
  // "Vulkan 1.1 (1.3 needed), no shaderBufferInt64Atomics".
  std::string missing;
};

const char* deviceTypeName(VkPhysicalDeviceType type);
// "1.3.230"
std::string versionString(uint32_t version);

class VulkanInstance {
 public:
  // Throws VulkanUnavailable when no Vulkan driver is installed, Error for
  // other problems (a loader older than 1.3, the validation layer missing).
  explicit VulkanInstance(const InstanceOptions& options = {});
  ~VulkanInstance();
  VulkanInstance(const VulkanInstance&) = delete;
  VulkanInstance& operator=(const VulkanInstance&) = delete;

  VkInstance handle() const { return instance_; }
  bool validation() const { return validation_; }
  DebugLog& log() const { return *log_; }
  const std::shared_ptr<DebugLog>& sharedLog() const { return log_; }
  // Every physical device with its facts, in the driver's order.
  const std::vector<DeviceInfo>& devices() const { return devices_; }

 private:
  void release();

  std::shared_ptr<DebugLog> log_;
  bool validation_ = false;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::vector<DeviceInfo> devices_;
};

}  // namespace fibscope::gpu
