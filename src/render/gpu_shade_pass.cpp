#include "render/gpu_shade_pass.h"

#include <string>

#include "core/error.h"
#include "gpu/submit.h"
#include "render/gpu_fiblet_passes.h"
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

void begin(VkCommandBuffer cmd, gpu::GpuTimer* timer, const char* name) {
  if (timer) gpu::beginPass(cmd, *timer, name);
}
void end(VkCommandBuffer cmd, gpu::GpuTimer* timer) {
  if (timer) gpu::endPass(cmd, *timer);
}

void createScratch(const gpu::VulkanContext& context, ShadePass& pass, uint32_t width, uint32_t height) {
  const VkDeviceSize bytes = VkDeviceSize(width) * height * sizeof(float);
  gpu::Buffer ao = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer ao_blur;
  try {
    ao_blur = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
  } catch (...) {
    gpu::destroyBuffer(context, ao);
    throw;
  }
  gpu::destroyBuffer(context, pass.ao);
  gpu::destroyBuffer(context, pass.ao_blur);
  pass.ao = ao;
  pass.ao_blur = ao_blur;
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
    createScratch(context, pass, width, height);
  } catch (...) {
    destroyShadePass(context, pass);
    throw;
  }
  return pass;
}

void destroyShadePass(const gpu::VulkanContext& context, ShadePass& pass) {
  gpu::destroyBuffer(context, pass.ao_blur);
  gpu::destroyBuffer(context, pass.ao);
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
}

void recordShade(VkCommandBuffer cmd, const ShadePass& pass, const GpuFrameTargets& frame,
                 const RenderSettings& settings, gpu::GpuTimer* timer) {
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
  push.color = frame.color.address;
  push.width = frame.width;
  push.height = frame.height;
  switch (settings.color) {
    case ColorMode::Solid: push.color_mode = shader::kShadeColorSolid; break;
    case ColorMode::Orientation: push.color_mode = shader::kShadeColorOrientation; break;
    case ColorMode::PerFiber: push.color_mode = shader::kShadeColorPerFiber; break;
    case ColorMode::Scalar:
    case ColorMode::Normal: push.color_mode = shader::kShadeColorOrientation; break;  // shaded next commit
  }
  push.lighting = settings.lighting == Lighting::IlluminatedLines ? shader::kShadeLightingIlluminated
                                                                  : shader::kShadeLightingNone;
  push.solid_r = settings.solid_color[0];
  push.solid_g = settings.solid_color[1];
  push.solid_b = settings.solid_color[2];
  push.background_r = settings.background[0];
  push.background_g = settings.background[1];
  push.background_b = settings.background[2];
  push.ambient = settings.light_ambient;
  push.diffuse = settings.light_diffuse;
  push.specular = settings.light_specular;
  push.shininess = settings.light_shininess;
  begin(cmd, timer, "shade");
  gpu::recordDispatch(cmd, pass.shade, push, groups_x, groups_y);
  end(cmd, timer);
}

}  // namespace fibscope
