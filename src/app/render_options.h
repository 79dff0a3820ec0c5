// Command-line options shared by `fibscope render` and `fibscope bench`:
// the input, the device, the frame size and the render settings.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "gpu/vulkan_context.h"
#include "render/gpu_dataset.h"
#include "render/gpu_frame_renderer.h"
#include "render/render_settings.h"

namespace CLI {
class App;
}

namespace fibscope {

struct RenderCliOptions {
  std::string input;  // empty: the built-in phantom
  uint64_t phantom_streamlines = 10000;
  std::string device;
  bool validate = false;
  std::string size = "1920x1080";
  std::string pipeline = "compute";
  std::string culling = "two-phase";
  std::string color = "orientation";
  std::string lighting = "illuminated";
  bool no_ssao = false;
  int ao_scales = 1;
  bool fxaa = false;
  std::string colormap = "viridis";
  std::string scalar_range;  // "MIN,MAX"; empty: the scalars' own range
  float line_width = 1.0f;
  float lod_pixels = 4.0f;  // far-view LoD: fiblets projected smaller drawn as one segment (0: off)
  std::string background = "0,0,0";
};

// Registers the options on `cmd`.
void addRenderCliOptions(CLI::App* cmd, RenderCliOptions& options);

// The settings and frame size the options name. Throws Error (one line) for
// an unknown name, a malformed size ("WxH", 1 to 16384 each) or background
// ("R,G,B" in [0, 1]), a line width outside [1, 4], AO scales outside
// [1, 4], or a malformed scalar range ("MIN,MAX", finite, MIN <= MAX).
RenderSettings renderSettingsFrom(const RenderCliOptions& options);
void parseFrameSize(const std::string& text, uint32_t& width, uint32_t& height);

// ColorMode::Scalar's source on the command line: the fibers' lengths in mm,
// already on the GPU with the dataset (GpuDataset::fiberLength), so nothing
// more is uploaded. With settings.color == Scalar: points scene.fiber_scalars
// at them and, when --scalar-range was not given, sets the settings' range
// to their min and max (read back once). Otherwise does nothing.
void applyScalarColoring(const gpu::VulkanContext& context, const GpuDataset& dataset, const RenderCliOptions& options,
                         RenderSettings& settings, GpuScene& scene);

// The Vulkan context the options ask for (validation layers with
// --validate, a device by name with --device).
std::unique_ptr<gpu::VulkanContext> createRenderContext(const RenderCliOptions& options);
// With --validate: Error when the layers reported anything.
void checkValidation(const gpu::VulkanContext& context, const RenderCliOptions& options);

}  // namespace fibscope
