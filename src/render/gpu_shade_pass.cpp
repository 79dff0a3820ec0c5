#include "render/gpu_shade_pass.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/submit.h"
#include "render/colormap.h"
#include "render/gpu_fiblet_passes.h"
#include "shared/render_config.h"
#include "shared/shade_push.h"

namespace fibscope {
namespace {

// Neighbours nearer than this (mm) do not occlude: fibers side by side in a
// bundle are at most a few tenths of a millimetre apart in depth across a
// few pixels.
constexpr float kSsaoEpsilonMm = 0.3f;
// The blur mixes pixels within this distance in depth: the same layer of a
// bundle, not an occluder with the fiber it darkens.
constexpr float kSsaoBlurDepthToleranceMm = 1.0f;
constexpr float kMaxSsaoRadiusPx = 64.0f;
// FXAA 3.11's quality-preset defaults: contrast below 1/8 of the local
// maximum luma (or below 1/16 absolute, for dark regions) is no edge;
// sub-pixel blending at three quarters.
constexpr float kFxaaEdgeThreshold = 0.125f;
constexpr float kFxaaEdgeThresholdMin = 0.0625f;
constexpr float kFxaaSubpix = 0.75f;

uint32_t packRgba8(const std::array<float, 3>& c) {
  uint32_t packed = 0xFF000000u;
  for (int k = 0; k < 3; ++k) packed |= uint32_t(std::clamp(c[k], 0.0f, 1.0f) * 255.0f + 0.5f) << (8 * k);
  return packed;
}

void begin(VkCommandBuffer cmd, gpu::GpuTimer* timer, const char* name) {
  if (timer) gpu::beginPass(cmd, *timer, name);
}
void end(VkCommandBuffer cmd, gpu::GpuTimer* timer) {
  if (timer) gpu::endPass(cmd, *timer);
}

void createScratch(const gpu::VulkanContext& context, ShadePass& pass, uint32_t width, uint32_t height) {
  // float and RGBA8 are both 4 bytes a pixel.
  const VkDeviceSize bytes = VkDeviceSize(width) * height * sizeof(float);
  gpu::Buffer ao = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer ao_blur, fxaa_input;
  try {
    ao_blur = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
    fxaa_input = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
  } catch (...) {
    gpu::destroyBuffer(context, ao_blur);
    gpu::destroyBuffer(context, ao);
    throw;
  }
  gpu::destroyBuffer(context, pass.ao);
  gpu::destroyBuffer(context, pass.ao_blur);
  gpu::destroyBuffer(context, pass.fxaa_input);
  pass.ao = ao;
  pass.ao_blur = ao_blur;
  pass.fxaa_input = fxaa_input;
  pass.width = width;
  pass.height = height;
}

bool inRange(float v, float lo, float hi) { return v >= lo && v <= hi; }  // false for NaN

}  // namespace

ShadePass createShadePass(const gpu::VulkanContext& context, uint32_t width, uint32_t height) {
  ShadePass pass;
  try {
    pass.ssao = gpu::createComputePipeline(context, "ssao.comp", sizeof(shader::SsaoPush));
    pass.ssao_blur = gpu::createComputePipeline(context, "ssao_blur.comp", sizeof(shader::SsaoBlurPush));
    pass.shade = gpu::createComputePipeline(context, "shade.comp", sizeof(shader::ShadePush));
    pass.fxaa = gpu::createComputePipeline(context, "fxaa.comp", sizeof(shader::FxaaPush));
    const std::vector<uint32_t> tables = allColormapTables();
    pass.colormaps = gpu::createBuffer(context, tables.size() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context, pass.colormaps, tables.data(), tables.size() * sizeof(uint32_t));
    createScratch(context, pass, width, height);
  } catch (...) {
    destroyShadePass(context, pass);
    throw;
  }
  return pass;
}

void destroyShadePass(const gpu::VulkanContext& context, ShadePass& pass) {
  gpu::destroyBuffer(context, pass.colormaps);
  gpu::destroyBuffer(context, pass.fxaa_input);
  gpu::destroyBuffer(context, pass.ao_blur);
  gpu::destroyBuffer(context, pass.ao);
  gpu::destroyComputePipeline(context, pass.fxaa);
  gpu::destroyComputePipeline(context, pass.shade);
  gpu::destroyComputePipeline(context, pass.ssao_blur);
  gpu::destroyComputePipeline(context, pass.ssao);
  pass.width = pass.height = 0;
}

void resizeShadePass(const gpu::VulkanContext& context, ShadePass& pass, uint32_t width, uint32_t height) {
  if (width == pass.width && height == pass.height) return;
  createScratch(context, pass, width, height);
}

void validateShadeSettings(const RenderSettings& s) {
  if (!inRange(s.ssao_radius_px, 0.0f, kMaxSsaoRadiusPx))
    throw Error("render: SSAO radius must lie in [0, 64] px, got " + std::to_string(s.ssao_radius_px));
  if (!inRange(s.ssao_strength, 0.0f, 1.0f))
    throw Error("render: SSAO strength must lie in [0, 1], got " + std::to_string(s.ssao_strength));
  if (!(s.ssao_range_mm > 0.0f) || !inRange(s.ssao_range_mm, 0.0f, 1e6f))
    throw Error("render: SSAO range must be a positive distance in mm, got " + std::to_string(s.ssao_range_mm));
  for (float k : {s.light_ambient, s.light_diffuse, s.light_specular})
    if (!inRange(k, 0.0f, 16.0f))
      throw Error("render: lighting coefficients must lie in [0, 16], got " + std::to_string(k));
  if (!inRange(s.light_shininess, 1.0f, 256.0f))
    throw Error("render: shininess must lie in [1, 256], got " + std::to_string(s.light_shininess));
  if (s.ao_scales < 1 || s.ao_scales > int(shader::kSsaoMaxScales))
    throw Error("render: AO scales must lie in [1, 4], got " + std::to_string(s.ao_scales));
  if (!std::isfinite(s.scalar_min) || !std::isfinite(s.scalar_max) || s.scalar_max < s.scalar_min)
    throw Error("render: scalar range must be finite with min <= max, got " + std::to_string(s.scalar_min) + ", " +
                std::to_string(s.scalar_max));
  for (float k : s.highlight_color)
    if (!inRange(k, 0.0f, 1.0f))
      throw Error("render: highlight colour components must lie in [0, 1], got " + std::to_string(k));
  if (!inRange(s.dim_unselected, 0.0f, 1.0f))
    throw Error("render: dimming of unselected fibers must lie in [0, 1], got " + std::to_string(s.dim_unselected));
  if (uint32_t(s.colormap) >= kColormapCount)
    throw Error("render: unknown colormap " + std::to_string(int(s.colormap)));
}

void recordFxaa(VkCommandBuffer cmd, const ShadePass& pass, const gpu::Buffer& input, const gpu::Buffer& output,
                uint32_t width, uint32_t height) {
  shader::FxaaPush push{};
  push.color_in = input.address;
  push.color_out = output.address;
  push.width = width;
  push.height = height;
  push.edge_threshold = kFxaaEdgeThreshold;
  push.edge_threshold_min = kFxaaEdgeThresholdMin;
  push.subpix = kFxaaSubpix;
  gpu::recordDispatch(cmd, pass.fxaa, push, (width + shader::kPixelGroupSize - 1) / shader::kPixelGroupSize,
                      (height + shader::kPixelGroupSize - 1) / shader::kPixelGroupSize);
}

void recordShade(VkCommandBuffer cmd, const ShadePass& pass, const GpuFrameTargets& frame,
                 const RenderSettings& settings, gpu::GpuTimer* timer, const ShadeFiberInputs& fibers) {
  validateShadeSettings(settings);
  if (frame.width != pass.width || frame.height != pass.height)
    throw Error("render: shading pass is " + std::to_string(pass.width) + " x " + std::to_string(pass.height) +
                " px, the frame " + std::to_string(frame.width) + " x " + std::to_string(frame.height));
  const uint32_t groups_x = pixelGroupsX(frame), groups_y = pixelGroupsY(frame);
  const bool ssao = settings.ssao && settings.ssao_radius_px > 0.0f && settings.ssao_strength > 0.0f;

  if (ssao) {
    shader::SsaoPush push{};
    push.camera = frame.camera.address;
    push.gbuffer = frame.gbuffer.address;
    push.ao = pass.ao.address;
    push.width = frame.width;
    push.height = frame.height;
    push.radius_px = settings.ssao_radius_px;
    push.epsilon_mm = kSsaoEpsilonMm;
    push.range_mm = settings.ssao_range_mm;
    push.strength = settings.ssao_strength;
    push.scales = uint32_t(settings.ao_scales);
    begin(cmd, timer, "ssao");
    gpu::recordDispatch(cmd, pass.ssao, push, groups_x, groups_y);
    end(cmd, timer);
    gpu::computeToComputeBarrier(cmd);

    shader::SsaoBlurPush blur{};
    blur.camera = frame.camera.address;
    blur.gbuffer = frame.gbuffer.address;
    blur.width = frame.width;
    blur.height = frame.height;
    blur.depth_tolerance_mm = kSsaoBlurDepthToleranceMm;
    begin(cmd, timer, "ssao blur");
    blur.ao_in = pass.ao.address;
    blur.ao_out = pass.ao_blur.address;
    blur.step_x = 1;
    blur.step_y = 0;
    gpu::recordDispatch(cmd, pass.ssao_blur, blur, groups_x, groups_y);
    gpu::computeToComputeBarrier(cmd);
    blur.ao_in = pass.ao_blur.address;
    blur.ao_out = pass.ao.address;
    blur.step_x = 0;
    blur.step_y = 1;
    gpu::recordDispatch(cmd, pass.ssao_blur, blur, groups_x, groups_y);
    end(cmd, timer);
    gpu::computeToComputeBarrier(cmd);
  }

  shader::ShadePush push{};
  push.camera = frame.camera.address;
  push.gbuffer = frame.gbuffer.address;
  push.ao = ssao ? pass.ao.address : 0;
  push.color = settings.fxaa ? pass.fxaa_input.address : frame.color.address;
  push.colormap = pass.colormaps.address + VkDeviceAddress(settings.colormap) * kColormapEntries * sizeof(uint32_t);
  push.fiber_scalars = fibers.fiber_scalars;
  push.selection_bits = fibers.selection_bits;
  push.fiber_count = fibers.fiber_count;
  push.width = frame.width;
  push.height = frame.height;
  switch (settings.color) {
    case ColorMode::Solid: push.color_mode = shader::kShadeColorSolid; break;
    case ColorMode::Orientation: push.color_mode = shader::kShadeColorOrientation; break;
    case ColorMode::PerFiber: push.color_mode = shader::kShadeColorPerFiber; break;
    case ColorMode::Scalar: push.color_mode = shader::kShadeColorScalar; break;
    case ColorMode::Normal: push.color_mode = shader::kShadeColorNormal; break;
  }
  push.lighting = settings.lighting == Lighting::IlluminatedLines ? shader::kShadeLightingIlluminated
                                                                  : shader::kShadeLightingNone;
  push.solid_r = settings.solid_color[0];
  push.solid_g = settings.solid_color[1];
  push.solid_b = settings.solid_color[2];
  push.background = packRgba8(settings.background);
  push.ambient = settings.light_ambient;
  push.diffuse = settings.light_diffuse;
  push.specular = settings.light_specular;
  push.shininess = settings.light_shininess;
  push.scalar_min = settings.scalar_min;
  push.scalar_max = settings.scalar_max;
  push.highlight = packRgba8(settings.highlight_color);
  push.dim_unselected = settings.dim_unselected;
  begin(cmd, timer, "shade");
  gpu::recordDispatch(cmd, pass.shade, push, groups_x, groups_y);
  end(cmd, timer);

  if (settings.fxaa) {
    gpu::computeToComputeBarrier(cmd);
    begin(cmd, timer, "fxaa");
    recordFxaa(cmd, pass, pass.fxaa_input, frame.color, frame.width, frame.height);
    end(cmd, timer);
  }
}

}  // namespace fibscope
