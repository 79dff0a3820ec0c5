// Command-line options shared by `fibscope render` and `fibscope bench`:
// the input, the device, the frame size and the render settings.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "app/criteria_options.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/dataset.h"
#include "render/gpu/frame_renderer.h"
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
  // The settings before the command line's (a command may change them
  // before addRenderCliOptions, e.g. render's frustum culling), then one
  // option per entry of render/settings_table.h: the text given for each
  // (empty: not given), and the flags (--fxaa, or --no-ssao for a flag on
  // by default).
  RenderSettings defaults;
  std::map<std::string, std::string, std::less<>> values;
  std::map<std::string, bool, std::less<>> flags;
  // The fiber filter (app/criteria_options.h; evaluated on the GPU by
  // app/scene_filter.h): dropped fibers hidden, or dimmed with dim_dropped.
  CriteriaCliOptions criteria;
  bool dim_dropped = false;
  // Cuts: --clip-plane PX,PY,PZ,NX,NY,NZ (repeatable; select/cuts.h), and
  // the planes and slab of --roi-set's set; --slab is a setting.
  std::vector<std::string> clip_planes;
  std::vector<std::string> cut_meshes;  // --cut-mesh SPEC:inside|outside (app/scene_cuts.h)
  // --anatomy: a NIfTI volume shown as slices (app/anatomy_options.h).
  std::string anatomy;
  // Whether the command line gave the setting `name`.
  bool gave(std::string_view name) const;
};

// Registers the options on `cmd`: every setting of the table as --NAME
// (its help and default from the table and `options.defaults`).
void addRenderCliOptions(CLI::App* cmd, RenderCliOptions& options);

// The settings the options name, with the cuts (the ROI set read). Throws
// Error (one line) naming the option or file and what it expects
// (render/settings_table.h: setSetting).
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
