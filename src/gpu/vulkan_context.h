// The device fibscope renders with: one physical device chosen by type (or
// by name), one logical device with the Vulkan 1.2/1.3 features the passes
// use, one queue that does compute, graphics and transfers, and a command
// pool for one-shot work. Use a context from one thread at a time.
#pragma once

#include <vulkan/vulkan.h>

#include <functional>
#include <span>
#include <string>

#include "gpu/vulkan_instance.h"

namespace fibscope::gpu {

struct ContextOptions {
  InstanceOptions instance;
  // Non-empty: the first device whose name contains this (case-insensitive),
  // else Error listing the devices. Empty: the best usable device.
  std::string device_name;
  // Set for a window: makes the surface right after the instance (e.g. with
  // glfwCreateWindowSurface; VK_NULL_HANDLE or an exception is a failure);
  // only devices whose queue family can present to it are considered, and
  // the device gets VK_KHR_swapchain. The context destroys the surface
  // before the instance. instance.extensions must name the surface
  // extensions the factory needs.
  std::function<VkSurfaceKHR(VkInstance)> surface_factory;
};

// The usable device of the best type (discrete GPU > integrated GPU >
// virtual GPU > CPU, e.g. lavapipe > other), the first of its type in driver
// order; or the first whose name contains `name`. Throws VulkanUnavailable
// when no device is usable (naming each device and what it lacks), Error when
// `name` matches no device or a device that lacks a feature.
const DeviceInfo& chooseDevice(std::span<const DeviceInfo> devices, const std::string& name);

// VK_EXT_mesh_shader (the mesh fiblet pipelines), enabled on the device
// where it has the extension with both its taskShader and meshShader
// features; never required.
struct MeshShaderSupport {
  bool enabled = false;
  // The device's limits (valid when enabled): maxMeshOutputVertices,
  // maxMeshOutputPrimitives, maxPreferredMeshWorkGroupInvocations, ...
  VkPhysicalDeviceMeshShaderPropertiesEXT properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_PROPERTIES_EXT};
  // Extension commands come from vkGetDeviceProcAddr (the loader exports
  // only core ones); null unless enabled.
  PFN_vkCmdDrawMeshTasksEXT cmdDrawMeshTasks = nullptr;
};

class VulkanContext {
 public:
  // Throws as VulkanInstance and chooseDevice do, or Error when the device
  // cannot be created.
  explicit VulkanContext(const ContextOptions& options = {});
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  const VulkanInstance& instance() const { return instance_; }
  DebugLog& log() const { return instance_.log(); }
  const DeviceInfo& info() const { return info_; }
  VkPhysicalDevice physicalDevice() const { return info_.handle; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return uint32_t(info_.queue_family); }
  VkCommandPool commandPool() const { return command_pool_; }
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memory_; }
  const VkPhysicalDeviceLimits& limits() const { return limits_; }
  // The core features enabled on the device: shaderInt64, and wideLines,
  // multiDrawIndirect and drawIndirectFirstInstance where the device has
  // them (the lines baseline falls back without them); geometryShader and
  // tessellationShader where the device has them (the geometry and
  // tessellation fiblet pipelines need them).
  const VkPhysicalDeviceFeatures& enabledFeatures() const { return enabled_; }
  const MeshShaderSupport& meshShader() const { return mesh_shader_; }
  // The window's surface (VK_NULL_HANDLE without a surface factory); the
  // device can present to it from queue().
  VkSurfaceKHR surface() const { return surface_; }

 private:
  void release();

  VulkanInstance instance_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  VkPhysicalDeviceMemoryProperties memory_{};
  VkPhysicalDeviceLimits limits_{};
  VkPhysicalDeviceFeatures enabled_{};
  MeshShaderSupport mesh_shader_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
};

}  // namespace fibscope::gpu
