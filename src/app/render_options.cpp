#include "app/render_options.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.h"
#include "render/colormap.h"

namespace fibscope {

void addRenderCliOptions(CLI::App* cmd, RenderCliOptions& o) {
  cmd->add_option("input", o.input, "Tractogram (.tck .trk .trx .vtk .fbl); none: the built-in phantom");
  cmd->add_option("--phantom-streamlines", o.phantom_streamlines, "Streamlines of the built-in phantom")
      ->capture_default_str();
  cmd->add_option("--size", o.size, "Frame size WxH in pixels")->capture_default_str();
  cmd->add_option("--pipeline", o.pipeline, "compute | lines | raw-compute")->capture_default_str();
  cmd->add_option("--culling", o.culling, "none | frustum | two-phase (compute pipeline)")->capture_default_str();
  cmd->add_option("--color", o.color, "orientation | solid | fiber | scalar (fiber length) | normal")
      ->capture_default_str();
  cmd->add_option("--colormap", o.colormap, "viridis | magma | grayscale | coolwarm (--color scalar)")
      ->capture_default_str();
  cmd->add_option("--scalar-range", o.scalar_range, "MIN,MAX mapped onto the colormap (default: the data's range)");
  cmd->add_option("--lighting", o.lighting, "illuminated | none")->capture_default_str();
  cmd->add_flag("--no-ssao", o.no_ssao, "No screen-space ambient occlusion");
  cmd->add_option("--ao-scales", o.ao_scales, "Multi-scale AO: 1 to 4 radii (r, 2r, 4r, 8r)")->capture_default_str();
  cmd->add_flag("--fxaa", o.fxaa, "Fast approximate anti-aliasing of the image");
  cmd->add_option("--line-width", o.line_width, "Line width in pixels, 1 to 4")->capture_default_str();
  cmd->add_option("--lod-pixels", o.lod_pixels,
                  "Far-view LoD: fiblets whose bounding sphere projects smaller are drawn as one segment "
                  "(frustum and two-phase culling; 0: off)")
      ->capture_default_str();
  cmd->add_option("--background", o.background, "Background colour R,G,B in [0, 1]")->capture_default_str();
  cmd->add_option("--device", o.device, "Vulkan device whose name contains this");
  cmd->add_flag("--validate", o.validate, "Vulkan validation layers on; any message is an error");
}

void parseFrameSize(const std::string& text, uint32_t& width, uint32_t& height) {
  unsigned long w = 0, h = 0;
  char x = 0, rest = 0;
  if (std::sscanf(text.c_str(), "%lu%c%lu%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X') || w < 1 ||
      h < 1 || w > 16384 || h > 16384)
    throw Error("--size: expected WxH with 1 to 16384 pixels each (e.g. 1920x1080), got '" + text + "'");
  width = uint32_t(w);
  height = uint32_t(h);
}

RenderSettings renderSettingsFrom(const RenderCliOptions& o) {
  RenderSettings s;
  s.pipeline = parseRenderPipeline(o.pipeline);
  s.culling = parseCullingMode(o.culling);
  s.color = parseColorMode(o.color);
  s.lighting = parseLighting(o.lighting);
  s.ssao = !o.no_ssao;
  if (o.ao_scales < 1 || o.ao_scales > 4)
    throw Error("--ao-scales: expected 1 to 4, got " + std::to_string(o.ao_scales));
  s.ao_scales = o.ao_scales;
  s.fxaa = o.fxaa;
  s.colormap = parseColormap(o.colormap);
  if (!o.scalar_range.empty()) {
    float lo = 0, hi = 0;
    char rest = 0;
    if (std::sscanf(o.scalar_range.c_str(), "%f,%f%c", &lo, &hi, &rest) != 2 || !std::isfinite(lo) ||
        !std::isfinite(hi) || hi < lo)
      throw Error("--scalar-range: expected MIN,MAX with MIN <= MAX, got '" + o.scalar_range + "'");
    s.scalar_min = lo;
    s.scalar_max = hi;
  }
  if (!(o.line_width >= 1.0f && o.line_width <= 4.0f))
    throw Error("--line-width: expected 1 to 4 pixels, got " + std::to_string(o.line_width));
  s.line_width_px = o.line_width;
  if (!(o.lod_pixels >= 0.0f && o.lod_pixels <= 4096.0f))
    throw Error("--lod-pixels: expected 0 to 4096 pixels, got " + std::to_string(o.lod_pixels));
  s.lod_pixels = o.lod_pixels;
  float r = 0, g = 0, b = 0;
  char rest = 0;
  if (std::sscanf(o.background.c_str(), "%f,%f,%f%c", &r, &g, &b, &rest) != 3 || !(r >= 0 && r <= 1) ||
      !(g >= 0 && g <= 1) || !(b >= 0 && b <= 1))
    throw Error("--background: expected R,G,B with each in [0, 1], got '" + o.background + "'");
  s.background = {r, g, b};
  return s;
}

void applyScalarColoring(const gpu::VulkanContext& context, const GpuDataset& dataset, const RenderCliOptions& o,
                         RenderSettings& settings, GpuScene& scene) {
  if (settings.color != ColorMode::Scalar) return;
  const uint32_t fibers = dataset.block().fiber_count;
  if (fibers == 0) return;
  scene.fiber_scalars = dataset.fiberLength().address;
  if (!o.scalar_range.empty()) return;
  std::vector<float> lengths(fibers);
  gpu::downloadFromBuffer(context, dataset.fiberLength(), lengths.data(), lengths.size() * sizeof(float));
  finiteRange(lengths, settings.scalar_min, settings.scalar_max);  // none finite: the default range stays
}

std::unique_ptr<gpu::VulkanContext> createRenderContext(const RenderCliOptions& o) {
  gpu::ContextOptions options;
  options.instance.validation = o.validate;
  options.device_name = o.device;
  return std::make_unique<gpu::VulkanContext>(options);
}

void checkValidation(const gpu::VulkanContext& context, const RenderCliOptions& o) {
  if (!o.validate) return;
  const int errors = context.log().errors(), warnings = context.log().warnings();
  if (errors + warnings > 0)
    throw Error("validation layers reported " + std::to_string(errors) + " errors and " + std::to_string(warnings) +
                " warnings (printed above)");
}

}  // namespace fibscope
