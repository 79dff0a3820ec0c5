#include "gpu/vulkan_instance.h"

#include <cstdio>
#include <cstring>

#include "gpu/leak_check_pins.h"
#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  static_cast<DebugLog*>(user)->add(severity, data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;  // never abort the call: the test decides what an error means
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(DebugLog* log) {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = debugCallback;
  info.pUserData = log;
  return info;
}

bool hasLayer(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

bool hasInstanceExtension(const char* layer, const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceExtensionProperties(layer, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> extensions(count);
  if (vkEnumerateInstanceExtensionProperties(layer, &count, extensions.data()) != VK_SUCCESS) return false;
  for (const auto& e : extensions)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

void appendMissing(std::string& missing, const std::string& what) {
  if (!missing.empty()) missing += ", ";
  missing += what;
}

DeviceInfo describeDevice(VkPhysicalDevice device, uint32_t index) {
  DeviceInfo info;
  info.index = index;
  info.handle = device;
  VkPhysicalDeviceProperties base;
  vkGetPhysicalDeviceProperties(device, &base);
  info.name = base.deviceName;
  info.type = base.deviceType;
  info.api_version = base.apiVersion;
  info.max_storage_buffer_range = base.limits.maxStorageBufferRange;
  info.max_push_constants_size = base.limits.maxPushConstantsSize;
  for (int i = 0; i < 3; ++i) info.max_compute_workgroup_count[i] = base.limits.maxComputeWorkGroupCount[i];
  info.timestamp_period_ns = base.limits.timestampPeriod;
  const uint32_t api =
      VK_MAKE_API_VERSION(0, VK_API_VERSION_MAJOR(base.apiVersion), VK_API_VERSION_MINOR(base.apiVersion), 0);

  // Structures of a newer core version may only be chained when the device
  // supports that version (the validation layer checks it).
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceMaintenance3Properties maintenance3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  if (api >= VK_API_VERSION_1_1) {
    props.pNext = &subgroup;
    subgroup.pNext = &maintenance3;
    if (api >= VK_API_VERSION_1_2) maintenance3.pNext = &driver;
    if (api >= VK_API_VERSION_1_2) features.pNext = &features12;
    if (api >= VK_API_VERSION_1_3) features12.pNext = &features13;
    vkGetPhysicalDeviceProperties2(device, &props);
    vkGetPhysicalDeviceFeatures2(device, &features);
    info.subgroup_size = subgroup.subgroupSize;
    info.subgroup_shuffle_relative = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                                     (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_RELATIVE_BIT);
    info.max_memory_allocation_size = maintenance3.maxMemoryAllocationSize;
    if (api >= VK_API_VERSION_1_2) {
      info.driver_name = driver.driverName;
      info.driver_info = driver.driverInfo;
    }
  } else {
    vkGetPhysicalDeviceFeatures(device, &features.features);
  }
  info.shader_int64 = features.features.shaderInt64;
  info.buffer_device_address = features12.bufferDeviceAddress;
  info.buffer_int64_atomics = features12.shaderBufferInt64Atomics;
  info.synchronization2 = features13.synchronization2;
  const bool maintenance4 = features13.maintenance4;
  const bool dynamic_rendering = features13.dynamicRendering;

  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  for (const auto& e : extensions)
    if (std::strcmp(e.extensionName, VK_EXT_MESH_SHADER_EXTENSION_NAME) == 0) info.mesh_shader = true;

  // One queue does everything: compute passes and the graphics pipelines
  // record into the same command buffers. Prefer a family with both.
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  for (uint32_t f = 0; f < count; ++f) {
    const bool compute = families[f].queueFlags & VK_QUEUE_COMPUTE_BIT;
    const bool graphics = families[f].queueFlags & VK_QUEUE_GRAPHICS_BIT;
    if (!compute || families[f].queueCount == 0) continue;
    if (info.queue_family < 0 || (graphics && !info.queue_has_graphics)) {
      info.queue_family = int(f);
      info.queue_has_graphics = graphics;
      info.timestamp_valid_bits = families[f].timestampValidBits;
    }
  }

  if (api < VK_API_VERSION_1_3)
    appendMissing(info.missing, "Vulkan " + versionString(base.apiVersion) + " (1.3 needed)");
  if (info.queue_family < 0) appendMissing(info.missing, "no compute queue");
  if (!info.buffer_device_address) appendMissing(info.missing, "no bufferDeviceAddress");
  if (!info.shader_int64) appendMissing(info.missing, "no shaderInt64");
  if (!info.buffer_int64_atomics) appendMissing(info.missing, "no shaderBufferInt64Atomics");
  if (!info.synchronization2) appendMissing(info.missing, "no synchronization2");
  if (api >= VK_API_VERSION_1_3 && !maintenance4) appendMissing(info.missing, "no maintenance4");
  if (api >= VK_API_VERSION_1_3 && !dynamic_rendering) appendMissing(info.missing, "no dynamicRendering");
  return info;
}

}  // namespace

void DebugLog::add(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* message) {
  const bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  const bool warning = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  if (!error && !warning) return;
  std::string line = std::string(error ? "error: " : "warning: ") + message;
  std::lock_guard lock(mutex_);
  (error ? errors_ : warnings_) += 1;
  if (echo_) std::fprintf(stderr, "vulkan: %s\n", line.c_str());
  messages_.push_back(std::move(line));
}

int DebugLog::errors() const {
  std::lock_guard lock(mutex_);
  return errors_;
}

int DebugLog::warnings() const {
  std::lock_guard lock(mutex_);
  return warnings_;
}

std::vector<std::string> DebugLog::messages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}

void DebugLog::clear() {
  std::lock_guard lock(mutex_);
  errors_ = warnings_ = 0;
  messages_.clear();
}

const char* deviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

std::string versionString(uint32_t version) {
  return std::to_string(VK_API_VERSION_MAJOR(version)) + "." + std::to_string(VK_API_VERSION_MINOR(version)) + "." +
         std::to_string(VK_API_VERSION_PATCH(version));
}

VulkanInstance::VulkanInstance(const InstanceOptions& options)
    : log_(options.log ? options.log : std::make_shared<DebugLog>(options.validation)),
      validation_(options.validation) {
  uint32_t loader_version = VK_API_VERSION_1_0;
  if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_3)
    throw Error("vulkan: the Vulkan loader is version " + versionString(loader_version) +
                ", fibscope needs 1.3 (install libvulkan1 from Debian 12 or newer)");

  std::vector<const char*> layers, extensions;
  bool debug_utils = false, validation_features = false;
  if (validation_) {
    if (!hasLayer(kValidationLayer))
      throw Error(std::string("vulkan: validation requested but ") + kValidationLayer +
                  " is not installed (install vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    validation_features = hasInstanceExtension(kValidationLayer, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    if (validation_features) extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  }
  // Debug utils carries the layer's messages; without validation it still
  // reports loader problems.
  if (hasInstanceExtension(nullptr, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) ||
      (validation_ && hasInstanceExtension(kValidationLayer, VK_EXT_DEBUG_UTILS_EXTENSION_NAME))) {
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    debug_utils = true;
  }
  // Portability drivers (MoltenVK) are listed only when asked for.
  const bool portability = hasInstanceExtension(nullptr, VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
  if (portability) extensions.push_back(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
  for (const std::string& name : options.extensions) {
    if (!hasInstanceExtension(nullptr, name.c_str()))
      throw Error("vulkan: the instance extension " + name + " is not available (a window needs it)");
    bool listed = false;
    for (const char* e : extensions) listed = listed || name == e;
    if (!listed) extensions.push_back(name.c_str());
  }

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "fibscope";
  app.applicationVersion = VK_MAKE_API_VERSION(0, 0, 1, 0);
  app.pEngineName = "fibscope";
  app.apiVersion = VK_API_VERSION_1_3;

  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  info.enabledLayerCount = uint32_t(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = uint32_t(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  if (portability) info.flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
  // Chained so that instance creation and destruction are reported too;
  // synchronisation validation catches missing barriers between passes.
  VkDebugUtilsMessengerCreateInfoEXT messenger_info = messengerInfo(log_.get());
  const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  if (debug_utils) info.pNext = &messenger_info;
  if (validation_features) {
    features.pNext = info.pNext;
    info.pNext = &features;
  }

  const VkResult result = vkCreateInstance(&info, nullptr, &instance_);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw VulkanUnavailable("vulkan: no Vulkan driver found (install mesa-vulkan-drivers)");
  throwIfFailed(result, "vkCreateInstance");

  try {
    if (debug_utils) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      if (create)
        throwIfFailed(create(instance_, &messenger_info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    }
    uint32_t count = 0;
    VkResult r = vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    if (r == VK_ERROR_INITIALIZATION_FAILED || (r == VK_SUCCESS && count == 0))
      throw VulkanUnavailable("vulkan: no Vulkan driver found (install mesa-vulkan-drivers)");
    throwIfFailed(r, "vkEnumeratePhysicalDevices");
    std::vector<VkPhysicalDevice> handles(count);
    r = vkEnumeratePhysicalDevices(instance_, &count, handles.data());
    if (r != VK_INCOMPLETE) throwIfFailed(r, "vkEnumeratePhysicalDevices");
    for (uint32_t i = 0; i < count; ++i) devices_.push_back(describeDevice(handles[i], i));
  } catch (...) {
    release();
    throw;
  }
}

VulkanInstance::~VulkanInstance() { release(); }

void VulkanInstance::release() {
  if (messenger_ != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
  }
  if (instance_ != VK_NULL_HANDLE) {
    // The driver goes with the instance: under LeakSanitizer keep it mapped
    // so its per-process allocations stay reachable (gpu/leak_check_pins.h).
    pinLibrariesForLeakChecks();
    vkDestroyInstance(instance_, nullptr);
  }
  instance_ = VK_NULL_HANDLE;
}

}  // namespace fibscope::gpu
