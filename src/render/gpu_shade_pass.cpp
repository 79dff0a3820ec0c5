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
#include "shared/cull_push.h"
#include "shared/fiblet_list.h"
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

uint64_t tileCount(uint32_t width, uint32_t height) {
  return uint64_t(shader::pixelGroups(width)) * shader::pixelGroups(height);
}

void createScratch(const gpu::VulkanContext& context, ShadePass& pass, uint32_t width, uint32_t height) {
  // float and RGBA8 are both 4 bytes a pixel.
  const VkDeviceSize bytes = VkDeviceSize(width) * height * sizeof(float);
  const uint64_t tiles = tileCount(width, height);
  gpu::Buffer ao, ao_blur, fxaa_input, tile_flags, tile_list;
  try {
    ao = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
    ao_blur = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
    fxaa_input = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
    tile_flags = gpu::createBuffer(context, tiles * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    tile_list = gpu::createBuffer(context, sizeof(shader::FibletListHeader) + tiles * sizeof(uint32_t),
                                  gpu::MemoryUse::DeviceLocal, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  } catch (...) {
    for (gpu::Buffer* b : {&tile_list, &tile_flags, &fxaa_input, &ao_blur, &ao}) gpu::destroyBuffer(context, *b);
    throw;
  }
  for (gpu::Buffer* b : {&pass.ao, &pass.ao_blur, &pass.fxaa_input, &pass.tile_flags, &pass.tile_list})
    gpu::destroyBuffer(context, *b);
  pass.ao = ao;
  pass.ao_blur = ao_blur;
  pass.fxaa_input = fxaa_input;
  pass.tile_flags = tile_flags;
  pass.tile_list = tile_list;
  pass.width = width;
  pass.height = height;
}

bool inRange(float v, float lo, float hi) { return v >= lo && v <= hi; }  // false for NaN

// One workgroup per covered tile: the list's own indirect command.
template <typename Push>
void dispatchTiles(VkCommandBuffer cmd, const gpu::ComputePipeline& pipeline, const Push& push,
                   const gpu::Buffer& tile_list) {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
  vkCmdPushConstants(cmd, pipeline.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
  vkCmdDispatchIndirect(cmd, tile_list.buffer, 0);
}

// Fills the output with the background, lists the covered tiles and makes
// the list's dispatch ready for the tile passes.
void recordTiles(VkCommandBuffer cmd, const ShadePass& pass,
                 const GpuFrameTargets& frame, const gpu::Buffer& output, uint32_t background) {
  const uint64_t tiles = tileCount(frame.width, frame.height);
  vkCmdFillBuffer(cmd, pass.tile_flags.buffer, 0, tiles * sizeof(uint32_t), 0);
  vkCmdFillBuffer(cmd, pass.tile_list.buffer, 0, sizeof(shader::FibletListHeader), 0);
  vkCmdFillBuffer(cmd, output.buffer, 0, VkDeviceSize(frame.width) * frame.height * sizeof(uint32_t), background);
  // The fills before the passes, and before the tile passes' indirect
  // reads of the list's header.
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                         VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
  shader::TileClassifyPush classify{};
  classify.gbuffer = frame.gbuffer.address;
  classify.flags = pass.tile_flags.address;
  classify.tiles = pass.tile_list.address;
  classify.width = frame.width;
  classify.height = frame.height;
  gpu::recordDispatch(cmd, pass.tile_classify, classify, pixelGroupsX(frame), pixelGroupsY(frame));
  gpu::computeToComputeBarrier(cmd);
  shader::FibletListFinalizePush finalize{};
  finalize.list = pass.tile_list.address;
  finalize.items_per_group = 1;
  finalize.max_groups_x = pass.max_groups_x;
  gpu::recordDispatch(cmd, pass.tile_finalize, finalize, 1);
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
}

}  // namespace

ShadePass createShadePass(const gpu::VulkanContext& context, uint32_t width, uint32_t height) {
  ShadePass pass;
  try {
    pass.tile_classify = gpu::createComputePipeline(context, "tile_classify.comp", sizeof(shader::TileClassifyPush));
    pass.tile_finalize =
        gpu::createComputePipeline(context, "fiblet_list_finalize.comp", sizeof(shader::FibletListFinalizePush));
    pass.ssao = gpu::createComputePipeline(context, "ssao.comp", sizeof(shader::SsaoPush));
    pass.ssao_blur = gpu::createComputePipeline(context, "ssao_blur.comp", sizeof(shader::SsaoBlurPush));
    pass.shade = gpu::createComputePipeline(context, "shade.comp", sizeof(shader::ShadePush));
    pass.fxaa = gpu::createComputePipeline(context, "fxaa.comp", sizeof(shader::FxaaPush));
    const std::vector<uint32_t> tables = allColormapTables();
    pass.colormaps = gpu::createBuffer(context, tables.size() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context, pass.colormaps, tables.data(), tables.size() * sizeof(uint32_t));
    pass.max_groups_x = context.limits().maxComputeWorkGroupCount[0];
    createScratch(context, pass, width, height);
  } catch (...) {
    destroyShadePass(context, pass);
    throw;
  }
  return pass;
}

void destroyShadePass(const gpu::VulkanContext& context, ShadePass& pass) {
  gpu::destroyBuffer(context, pass.colormaps);
  gpu::destroyBuffer(context, pass.tile_list);
  gpu::destroyBuffer(context, pass.tile_flags);
  gpu::destroyBuffer(context, pass.fxaa_input);
  gpu::destroyBuffer(context, pass.ao_blur);
  gpu::destroyBuffer(context, pass.ao);
  gpu::destroyComputePipeline(context, pass.fxaa);
  gpu::destroyComputePipeline(context, pass.shade);
  gpu::destroyComputePipeline(context, pass.ssao_blur);
  gpu::destroyComputePipeline(context, pass.ssao);
  gpu::destroyComputePipeline(context, pass.tile_finalize);
  gpu::destroyComputePipeline(context, pass.tile_classify);
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
  gpu::recordDispatch(cmd, pass.fxaa, push, shader::pixelGroups(width), shader::pixelGroups(height));
}

void recordShade(VkCommandBuffer cmd, const ShadePass& pass, const GpuFrameTargets& frame,
                 const RenderSettings& settings, gpu::GpuTimer* timer, const ShadeFiberInputs& fibers) {
  validateShadeSettings(settings);
  if (frame.width != pass.width || frame.height != pass.height)
    throw Error("render: shading pass is " + std::to_string(pass.width) + " x " + std::to_string(pass.height) +
                " px, the frame " + std::to_string(frame.width) + " x " + std::to_string(frame.height));
  const bool ssao = settings.ssao && settings.ssao_radius_px > 0.0f && settings.ssao_strength > 0.0f;
  const gpu::Buffer& output = settings.fxaa ? pass.fxaa_input : frame.color;
  begin(cmd, timer, "tiles");
  recordTiles(cmd, pass, frame, output, packRgba8(settings.background));
  end(cmd, timer);

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
    push.tiles = pass.tile_list.address;
    begin(cmd, timer, "ssao");
    dispatchTiles(cmd, pass.ssao, push, pass.tile_list);
    end(cmd, timer);
    gpu::computeToComputeBarrier(cmd);

    shader::SsaoBlurPush blur{};
    blur.camera = frame.camera.address;
    blur.gbuffer = frame.gbuffer.address;
    blur.width = frame.width;
    blur.height = frame.height;
    blur.depth_tolerance_mm = kSsaoBlurDepthToleranceMm;
    blur.tiles = pass.tile_list.address;
    begin(cmd, timer, "ssao blur");
    blur.ao_in = pass.ao.address;
    blur.ao_out = pass.ao_blur.address;
    blur.step_x = 1;
    blur.step_y = 0;
    dispatchTiles(cmd, pass.ssao_blur, blur, pass.tile_list);
    gpu::computeToComputeBarrier(cmd);
    blur.ao_in = pass.ao_blur.address;
    blur.ao_out = pass.ao.address;
    blur.step_x = 0;
    blur.step_y = 1;
    dispatchTiles(cmd, pass.ssao_blur, blur, pass.tile_list);
    end(cmd, timer);
    gpu::computeToComputeBarrier(cmd);
  }

  shader::ShadePush push{};
  push.camera = frame.camera.address;
  push.gbuffer = frame.gbuffer.address;
  push.ao = ssao ? pass.ao.address : 0;
  push.color = output.address;
  push.tiles = pass.tile_list.address;
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
  push.solid = packRgba8(settings.solid_color);
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
  dispatchTiles(cmd, pass.shade, push, pass.tile_list);
  end(cmd, timer);

  if (settings.fxaa) {
    gpu::computeToComputeBarrier(cmd);
    begin(cmd, timer, "fxaa");
    recordFxaa(cmd, pass, pass.fxaa_input, frame.color, frame.width, frame.height);
    end(cmd, timer);
  }
}

}  // namespace fibscope
