// The per-frame GPU buffers every pipeline shares (DESIGN.md section 6): the
// camera block, the 64-bit visibility buffer, the G-buffer and the shaded
// RGBA8 output, all plain storage buffers reached by device address. The
// lines baseline also needs an R32G32B32A32_UINT colour attachment and a
// depth attachment; its pass owns those.
#pragma once

#include <cstdint>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "shared/camera.h"
#include "shared/gbuffer.h"

namespace fibscope {

struct GpuFrameTargets {
  uint32_t width = 0, height = 0;
  gpu::Buffer camera;      // one CameraBlock, updated in the command buffer each frame
  gpu::Buffer visibility;  // uint64_t key per pixel, in 4 x 2 blocks (shared/render_config.h: visibilityIndex)
  gpu::Buffer gbuffer;     // GBufferTexel per pixel (shared/gbuffer.h)
  gpu::Buffer color;       // RGBA8 per pixel as one uint (R in the low byte), top row first
  // Optional (empty: address 0): the packed tangent of every segment the
  // fiblet rasters draw, a uint at fiblet * 64 + segment, so the resolve
  // reads it instead of decoding the fiblet again per pixel (render_push.h).
  gpu::Buffer tangents;
  // Shading scratch (shading_stages.h): occlusion per pixel (float; the
  // ssao stage writes ao, its x blur ao_blur, its y blur ao again), the
  // unfiltered shaded image FXAA reads (RGBA8), a flag per 8 x 8 tile and
  // the covered tiles (shared/fiblet_list.h layout, an indirect dispatch).
  gpu::Buffer ao, ao_blur, shaded, tile_flags, tile_list;
  // The surface target (SurfaceTexel per pixel, shared/gbuffer.h): made by
  // ensureSurfaceTarget at the first frame with surfaces.
  gpu::Buffer surface;
  uint64_t pixels() const { return uint64_t(width) * height; }
  // 8 x 8 tiles covering the frame.
  uint64_t tiles() const;
};

// Buffers for a width x height frame. Throws Error for an empty size, a
// size above 16384 px per side, or when memory runs out.
GpuFrameTargets createFrameTargets(const gpu::VulkanContext& context, uint32_t width, uint32_t height);
void destroyFrameTargets(const gpu::VulkanContext& context, GpuFrameTargets& targets);

// Makes targets.surface when it does not exist yet. Throws Error when
// memory runs out.
void ensureSurfaceTarget(const gpu::VulkanContext& context, GpuFrameTargets& targets);

// The tangent cache's budget: 256 bytes a fiblet (4 times its record) is
// worth it below this, or a quarter of the device-local heap if smaller;
// larger datasets resolve by decoding.
inline constexpr uint64_t kTangentCacheBudget = uint64_t(1) << 30;
// Makes targets.tangents hold `fiblets` fiblets when that fits the budget
// (reusing a large enough buffer), else releases it. Call outside of any
// recording that uses the old buffer (waits for the device when it
// replaces a buffer).
void prepareTangentCache(const gpu::VulkanContext& context, GpuFrameTargets& targets, uint32_t fiblets);

// Read-backs for tests and PNG output (wait for the queue).
std::vector<uint8_t> downloadColor(const gpu::VulkanContext& context, const GpuFrameTargets& targets);
std::vector<shader::GBufferTexel> downloadGBuffer(const gpu::VulkanContext& context, const GpuFrameTargets& targets);
// Empty when the targets have no surface target.
std::vector<shader::SurfaceTexel> downloadSurface(const gpu::VulkanContext& context, const GpuFrameTargets& targets);
// The keys row by row (the buffer holds them in 4 x 2 blocks: visibilityIndex).
std::vector<uint64_t> downloadVisibility(const gpu::VulkanContext& context, const GpuFrameTargets& targets);

}  // namespace fibscope
