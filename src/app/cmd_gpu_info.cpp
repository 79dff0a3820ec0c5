// `fibscope gpu-info [--validate] [--device NAME]`: the Vulkan devices, the
// one fibscope would render with and why, and the facts that decide which
// pipelines it can run (subgroup size, storage-buffer range, 64-bit atomics,
// mesh shaders). Creating the device proves the driver works; with
// --validate the validation layers watch that too.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <string>

#include "app/commands.h"
#include "core/error.h"
#include "gpu/vulkan_context.h"

namespace fibscope {
namespace {

struct GpuInfoOptions {
  bool validate = false;
  std::string device;
};

std::string sizeText(uint64_t bytes) {
  if (bytes >= (uint64_t(1) << 30) && bytes % (uint64_t(1) << 30) == 0) return std::to_string(bytes >> 30) + " GiB";
  if (bytes >= (uint64_t(1) << 20)) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

const char* yesNo(bool b) { return b ? "yes" : "no"; }

void printDevice(const gpu::DeviceInfo& d, bool chosen) {
  std::printf("%s %u: %s (%s)\n", chosen ? "*" : " ", d.index, d.name.c_str(), gpu::deviceTypeName(d.type));
  std::printf("      Vulkan %s, driver %s%s%s\n", gpu::versionString(d.api_version).c_str(),
              d.driver_name.empty() ? "?" : d.driver_name.c_str(), d.driver_info.empty() ? "" : " ",
              d.driver_info.c_str());
  std::printf("      subgroup size %u, max storage buffer range %s, max allocation %s, push constants %u bytes\n",
              d.subgroup_size, sizeText(d.max_storage_buffer_range).c_str(),
              sizeText(d.max_memory_allocation_size).c_str(), d.max_push_constants_size);
  std::printf("      buffer device address %s, 64-bit integers %s, 64-bit buffer atomics %s, mesh shaders %s\n",
              yesNo(d.buffer_device_address), yesNo(d.shader_int64), yesNo(d.buffer_int64_atomics),
              yesNo(d.mesh_shader));
  if (d.queue_family >= 0)
    std::printf("      queue family %d (%s), timestamps %u bits, %.3g ns per tick\n", d.queue_family,
                d.queue_has_graphics ? "graphics + compute" : "compute only", d.timestamp_valid_bits,
                double(d.timestamp_period_ns));
  std::printf("      %s\n", d.missing.empty() ? "usable" : ("not usable: " + d.missing).c_str());
}

void runGpuInfo(const GpuInfoOptions& options) {
  gpu::ContextOptions context_options;
  context_options.instance.validation = options.validate;
  context_options.device_name = options.device;
  // The instance alone first, so that the device list is shown even when no
  // device can be chosen.
  {
    const gpu::VulkanInstance instance(context_options.instance);
    uint32_t loader = 0;
    vkEnumerateInstanceVersion(&loader);
    std::printf("Vulkan loader %s, validation %s\n", gpu::versionString(loader).c_str(),
                options.validate ? "on" : "off");
    const gpu::DeviceInfo* chosen = nullptr;
    try {
      chosen = &gpu::chooseDevice(instance.devices(), options.device);
    } catch (const Error&) {
      for (const gpu::DeviceInfo& d : instance.devices()) printDevice(d, false);
      std::fflush(stdout);  // the list before main()'s error line
      throw;
    }
    for (const gpu::DeviceInfo& d : instance.devices()) printDevice(d, &d == chosen);
  }
  const gpu::VulkanContext context(context_options);
  std::printf("chosen: %s (device %u), device created\n", context.info().name.c_str(), context.info().index);
  const gpu::MeshShaderSupport& mesh = context.meshShader();
  if (mesh.enabled) {
    const VkPhysicalDeviceMeshShaderPropertiesEXT& p = mesh.properties;
    std::printf("mesh shaders: enabled (pipelines mesh, mesh-serial); output vertices %u, primitives %u, "
                "mesh workgroup invocations %u (preferred %u), task %u (preferred %u), task payload %u bytes\n",
                p.maxMeshOutputVertices, p.maxMeshOutputPrimitives, p.maxMeshWorkGroupInvocations,
                p.maxPreferredMeshWorkGroupInvocations, p.maxTaskWorkGroupInvocations,
                p.maxPreferredTaskWorkGroupInvocations, p.maxTaskPayloadSize);
  } else {
    std::printf("mesh shaders: VK_EXT_mesh_shader not supported by %s (pipelines mesh, mesh-serial unavailable)\n",
                context.info().name.c_str());
  }
  if (options.validate)
    std::printf("validation: %d errors, %d warnings\n", context.log().errors(), context.log().warnings());
}

}  // namespace

void addGpuInfoCommand(CLI::App& app) {
  auto options = std::make_shared<GpuInfoOptions>();
  CLI::App* cmd = app.add_subcommand("gpu-info", "List Vulkan devices and the one fibscope renders with");
  cmd->add_flag("--validate", options->validate, "Enable the Vulkan validation layers");
  cmd->add_option("--device", options->device, "Use the first device whose name contains NAME (case-insensitive)")
      ->option_text("NAME");
  cmd->callback([options] { runGpuInfo(*options); });
}

}  // namespace fibscope
