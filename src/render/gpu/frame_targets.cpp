#include "render/gpu/frame_targets.h"

#include <algorithm>
#include <string>

#include "core/error.h"
#include "render/gpu/dataset.h"
#include "shared/fiblet_list.h"
#include "shared/render_config.h"

namespace fibscope {

namespace {
constexpr uint32_t kMaxFrameSide = 16384;
}

GpuFrameTargets createFrameTargets(const gpu::VulkanContext& context, uint32_t width, uint32_t height) {
  if (width == 0 || height == 0 || width > kMaxFrameSide || height > kMaxFrameSide)
    throw Error("frame size must be 1 to " + std::to_string(kMaxFrameSide) + " px per side, got " +
                std::to_string(width) + " x " + std::to_string(height));
  GpuFrameTargets t;
  t.width = width;
  t.height = height;
  try {
    t.camera = gpu::createBuffer(context, sizeof(shader::CameraBlock), gpu::MemoryUse::DeviceLocal);
    t.visibility = gpu::createBuffer(context, uint64_t(shader::visibilityKeyCount(width, height)) * sizeof(uint64_t),
                                     gpu::MemoryUse::DeviceLocal);
    t.gbuffer = gpu::createBuffer(context, t.pixels() * sizeof(shader::GBufferTexel), gpu::MemoryUse::DeviceLocal);
    t.color = gpu::createBuffer(context, t.pixels() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    // float and RGBA8 are both 4 bytes a pixel.
    t.ao = gpu::createBuffer(context, t.pixels() * sizeof(float), gpu::MemoryUse::DeviceLocal);
    t.ao_blur = gpu::createBuffer(context, t.pixels() * sizeof(float), gpu::MemoryUse::DeviceLocal);
    t.shaded = gpu::createBuffer(context, t.pixels() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    t.tile_flags = gpu::createBuffer(context, t.tiles() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    t.tile_list = gpu::createBuffer(context, sizeof(shader::FibletListHeader) + t.tiles() * sizeof(uint32_t),
                                    gpu::MemoryUse::DeviceLocal, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  } catch (...) {
    destroyFrameTargets(context, t);
    throw;
  }
  return t;
}

uint64_t GpuFrameTargets::tiles() const { return uint64_t(shader::pixelGroups(width)) * shader::pixelGroups(height); }

void ensureSurfaceTarget(const gpu::VulkanContext& context, GpuFrameTargets& targets) {
  if (targets.surface.buffer) return;
  targets.surface =
      gpu::createBuffer(context, targets.pixels() * sizeof(shader::SurfaceTexel), gpu::MemoryUse::DeviceLocal);
}

void destroyFrameTargets(const gpu::VulkanContext& context, GpuFrameTargets& targets) {
  gpu::destroyBuffer(context, targets.surface);
  for (gpu::Buffer* b : {&targets.tile_list, &targets.tile_flags, &targets.shaded, &targets.ao_blur, &targets.ao})
    gpu::destroyBuffer(context, *b);
  gpu::destroyBuffer(context, targets.tangents);
  gpu::destroyBuffer(context, targets.color);
  gpu::destroyBuffer(context, targets.gbuffer);
  gpu::destroyBuffer(context, targets.visibility);
  gpu::destroyBuffer(context, targets.camera);
  targets = {};
}

void prepareTangentCache(const gpu::VulkanContext& context, GpuFrameTargets& targets, uint32_t fiblets) {
  const uint64_t bytes = uint64_t(fiblets) * 64 * sizeof(uint32_t);
  const DeviceLimits limits = deviceLimits(context);
  const uint64_t budget = std::min({kTangentCacheBudget, limits.device_local_heap_bytes / 4, limits.max_allocation_bytes});
  const bool wanted = fiblets > 0 && bytes <= budget;
  if (wanted && targets.tangents.size >= bytes) return;  // the buffer already holds it
  if (targets.tangents.buffer) {
    vkDeviceWaitIdle(context.device());  // earlier frames may still write it
    gpu::destroyBuffer(context, targets.tangents);
  }
  if (!wanted) return;
  try {
    targets.tangents = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
  } catch (const Error&) {
    // Out of memory: no cache (address 0), the resolve decodes.
  }
}

std::vector<uint8_t> downloadColor(const gpu::VulkanContext& context, const GpuFrameTargets& targets) {
  std::vector<uint8_t> rgba(targets.pixels() * 4);
  gpu::downloadFromBuffer(context, targets.color, rgba.data(), rgba.size());
  return rgba;
}

std::vector<shader::GBufferTexel> downloadGBuffer(const gpu::VulkanContext& context, const GpuFrameTargets& targets) {
  std::vector<shader::GBufferTexel> texels(targets.pixels());
  gpu::downloadFromBuffer(context, targets.gbuffer, texels.data(), texels.size() * sizeof(shader::GBufferTexel));
  return texels;
}

std::vector<shader::SurfaceTexel> downloadSurface(const gpu::VulkanContext& context, const GpuFrameTargets& targets) {
  if (!targets.surface.buffer) return {};
  std::vector<shader::SurfaceTexel> texels(targets.pixels());
  gpu::downloadFromBuffer(context, targets.surface, texels.data(), texels.size() * sizeof(shader::SurfaceTexel));
  return texels;
}

std::vector<uint64_t> downloadVisibility(const gpu::VulkanContext& context, const GpuFrameTargets& targets) {
  std::vector<uint64_t> blocks(shader::visibilityKeyCount(targets.width, targets.height));
  gpu::downloadFromBuffer(context, targets.visibility, blocks.data(), blocks.size() * sizeof(uint64_t));
  std::vector<uint64_t> keys(targets.pixels());
  for (uint32_t y = 0; y < targets.height; ++y)
    for (uint32_t x = 0; x < targets.width; ++x)
      keys[size_t(y) * targets.width + x] = blocks[shader::visibilityIndex(x, y, targets.width)];
  return keys;
}

}  // namespace fibscope
