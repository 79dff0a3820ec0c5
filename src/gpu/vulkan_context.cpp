#include "gpu/vulkan_context.h"

#include <algorithm>
#include <cctype>
#include <string_view>
#include <vector>

#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 3;
    default:
      return 4;
  }
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

std::string deviceList(std::span<const DeviceInfo> devices, bool with_missing) {
  std::string list;
  for (const DeviceInfo& d : devices) {
    if (!list.empty()) list += "; ";
    list += d.name;
    if (with_missing && !d.missing.empty()) list += ": " + d.missing;
  }
  return list.empty() ? "none" : list;
}

// The devices with "cannot present to the window" added to what they lack
// when their queue family cannot present to `surface` (or they have no
// VK_KHR_swapchain).
std::vector<DeviceInfo> presentableDevices(std::span<const DeviceInfo> devices, VkSurfaceKHR surface) {
  std::vector<DeviceInfo> result(devices.begin(), devices.end());
  for (DeviceInfo& d : result) {
    VkBool32 supported = VK_FALSE;
    if (d.queue_family >= 0 &&
        vkGetPhysicalDeviceSurfaceSupportKHR(d.handle, uint32_t(d.queue_family), surface, &supported) != VK_SUCCESS)
      supported = VK_FALSE;
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(d.handle, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(d.handle, nullptr, &count, extensions.data());
    bool swapchain = false;
    for (const auto& e : extensions)
      swapchain = swapchain || std::string_view(e.extensionName) == VK_KHR_SWAPCHAIN_EXTENSION_NAME;
    if (!supported || !swapchain) {
      if (!d.missing.empty()) d.missing += ", ";
      d.missing += "cannot present to the window";
    }
  }
  return result;
}

}  // namespace

const DeviceInfo& chooseDevice(std::span<const DeviceInfo> devices, const std::string& name) {
  if (!name.empty()) {
    const std::string wanted = lower(name);
    for (const DeviceInfo& d : devices) {
      if (lower(d.name).find(wanted) == std::string::npos) continue;
      if (!d.missing.empty()) throw Error("vulkan: device " + d.name + " cannot run fibscope: " + d.missing);
      return d;
    }
    throw Error("vulkan: no device name contains \"" + name + "\" (devices: " + deviceList(devices, false) + ")");
  }
  const DeviceInfo* best = nullptr;
  for (const DeviceInfo& d : devices)
    if (d.missing.empty() && (!best || typeRank(d.type) < typeRank(best->type))) best = &d;
  if (!best) throw VulkanUnavailable("vulkan: no device can run fibscope (" + deviceList(devices, true) + ")");
  return *best;
}

VulkanContext::VulkanContext(const ContextOptions& options) : instance_(options.instance) {
  try {
    if (options.surface_factory) {
      surface_ = options.surface_factory(instance_.handle());
      if (surface_ == VK_NULL_HANDLE) throw Error("vulkan: the window's surface could not be created");
      info_ = chooseDevice(presentableDevices(instance_.devices(), surface_), options.device_name);
    } else {
      info_ = chooseDevice(instance_.devices(), options.device_name);
    }
  } catch (...) {
    release();
    throw;
  }
  vkGetPhysicalDeviceMemoryProperties(info_.handle, &memory_);
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(info_.handle, &properties);
  limits_ = properties.limits;

  // Only what the passes use: buffer device addresses for every buffer (no
  // descriptor sets for data), 64-bit integers and atomics for the
  // visibility buffer, synchronization2 barriers, dynamic rendering.
  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  features13.synchronization2 = VK_TRUE;
  // glslc's Vulkan 1.3 SPIR-V declares workgroup sizes with LocalSizeId,
  // which needs maintenance4 (a feature every 1.3 device has).
  features13.maintenance4 = VK_TRUE;
  features13.dynamicRendering = VK_TRUE;  // graphics passes without render pass objects
  VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  features12.pNext = &features13;
  features12.bufferDeviceAddress = VK_TRUE;
  features12.shaderBufferInt64Atomics = VK_TRUE;
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features.pNext = &features12;
  features.features.shaderInt64 = VK_TRUE;
  // Optional: the lines baseline draws every streamline with one
  // vkCmdDrawIndirect (firstInstance = the streamline) and wide lines where
  // the device has them, and falls back to direct draws and width 1.
  VkPhysicalDeviceFeatures available{};
  vkGetPhysicalDeviceFeatures(info_.handle, &available);
  features.features.wideLines = available.wideLines;
  // The lines baseline clips at the cuts' planes with gl_ClipDistance.
  features.features.shaderClipDistance = available.shaderClipDistance;
  features.features.multiDrawIndirect = available.multiDrawIndirect;
  features.features.drawIndirectFirstInstance = available.drawIndirectFirstInstance;
  // The paper's comparison pipelines (geometry, tessellation) where the
  // device has the stages; without them those pipelines are refused in one
  // line.
  features.features.geometryShader = available.geometryShader;
  // The fragment-shader tube caster's atomicMin into its visibility buffer.
  features.features.fragmentStoresAndAtomics = available.fragmentStoresAndAtomics;
  features.features.tessellationShader = available.tessellationShader;
  enabled_ = features.features;

  // The mesh pipelines' stages where the device has them; their limits are
  // checked when a mesh pipeline is made (fiblet_mesh_pass.cpp).
  VkPhysicalDeviceMeshShaderFeaturesEXT mesh_features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
  std::vector<const char*> extensions;
  if (info_.mesh_shader) {
    VkPhysicalDeviceFeatures2 query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    query.pNext = &mesh_features;
    vkGetPhysicalDeviceFeatures2(info_.handle, &query);
    if (mesh_features.taskShader && mesh_features.meshShader) {
      // Only the two stages (not multiview, shading rate or queries).
      mesh_features = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
      mesh_features.taskShader = VK_TRUE;
      mesh_features.meshShader = VK_TRUE;
      features13.pNext = &mesh_features;
      extensions.push_back(VK_EXT_MESH_SHADER_EXTENSION_NAME);
      mesh_shader_.enabled = true;
      VkPhysicalDeviceProperties2 properties2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
      properties2.pNext = &mesh_shader_.properties;
      vkGetPhysicalDeviceProperties2(info_.handle, &properties2);
      mesh_shader_.properties.pNext = nullptr;
    }
  }

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = uint32_t(info_.queue_family);
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;

  if (surface_ != VK_NULL_HANDLE) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &features;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue_info;
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.empty() ? nullptr : extensions.data();
  const VkResult created = vkCreateDevice(info_.handle, &info, nullptr, &device_);
  if (created != VK_SUCCESS) {
    device_ = VK_NULL_HANDLE;
    release();
    throwIfFailed(created, "vkCreateDevice on " + info_.name);
  }
  vkGetDeviceQueue(device_, queueFamily(), 0, &queue_);
  if (mesh_shader_.enabled) {
    mesh_shader_.cmdDrawMeshTasks =
        reinterpret_cast<PFN_vkCmdDrawMeshTasksEXT>(vkGetDeviceProcAddr(device_, "vkCmdDrawMeshTasksEXT"));
    mesh_shader_.enabled = mesh_shader_.cmdDrawMeshTasks != nullptr;
  }

  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT | VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool_info.queueFamilyIndex = queueFamily();
  const VkResult r = vkCreateCommandPool(device_, &pool_info, nullptr, &command_pool_);
  if (r != VK_SUCCESS) {
    release();
    throwIfFailed(r, "vkCreateCommandPool");
  }
}

VulkanContext::~VulkanContext() { release(); }

void VulkanContext::release() {
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    if (command_pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, command_pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  command_pool_ = VK_NULL_HANDLE;
  device_ = VK_NULL_HANDLE;
  // Before the instance (a member destroyed after this).
  if (surface_ != VK_NULL_HANDLE) vkDestroySurfaceKHR(instance_.handle(), surface_, nullptr);
  surface_ = VK_NULL_HANDLE;
}

}  // namespace fibscope::gpu
