// Picking: which fiber is drawn at a pixel, read from the G-buffer of the
// last frame (shaders/shared/gbuffer.h), and where it lies in the world.
//
// One 16-byte texel is copied from GpuFrameTargets::gbuffer into a small
// host-visible buffer, so a click costs a copy of 16 bytes, not a download
// of the frame. The viewer records the copy after its frame (one frame in
// flight: the texel is read after the frame's fence) or uses pickFiber,
// which submits and waits.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu/frame_targets.h"

namespace fibscope {

struct PickResult {
  bool hit = false;     // a fiber is drawn at the pixel
  uint32_t fiber = 0;   // streamline index (valid when hit)
  uint32_t segment = 0; // the G-buffer's pipeline-specific segment index (gbuffer.h)
  float depth = 1.0f;   // clip depth z/w in [0, 1]; 1 when nothing is drawn
  // A surface was picked (shared/gbuffer.h: kGBufferSurface): `fiber` is
  // the surface's fiber or object id (a sphere's id), `source` who drew it
  // (kSurfaceSource*).
  bool surface = false;
  uint32_t source = 0;
};

// Bytes a pick read-back buffer needs (one GBufferTexel).
inline constexpr VkDeviceSize kPickBufferBytes = sizeof(shader::GBufferTexel);
// A host-visible buffer for recordPickReadback (MemoryUse::Readback,
// kPickBufferBytes). Destroy with gpu::destroyBuffer.
gpu::Buffer createPickBuffer(const gpu::VulkanContext& context);

// Records: a barrier making every earlier write of the G-buffer (compute
// shader stores, or the lines pipeline's copy) visible to a transfer read;
// the copy of the texel of pixel (x, y) (top row first) into the first 16
// bytes of `host_dst`; a barrier making the copy visible to the host.
// A pixel outside the targets records the barriers and writes a no-hit
// texel with vkCmdFillBuffer instead, so readPick reports no hit and no copy
// ever reads outside the G-buffer. `host_dst` must be a host-visible buffer
// of at least kPickBufferBytes (Error otherwise).
void recordPickReadback(VkCommandBuffer cmd, const GpuFrameTargets& targets, uint32_t x, uint32_t y,
                        const gpu::Buffer& host_dst);
// Decodes the texel recorded above once the command buffer has completed
// (invalidates the mapped range when the memory is not coherent).
PickResult readPick(const gpu::VulkanContext& context, const gpu::Buffer& host_dst);
// The texel as a PickResult (hit when fiber != kNoFiberId).
PickResult decodePick(const shader::GBufferTexel& texel);

// Convenience: a temporary read-back buffer, recordPickReadback, submit and
// wait. The GPU must have finished (or have been given) the frame that wrote
// the G-buffer on the same queue.
PickResult pickFiber(const gpu::VulkanContext& context, const GpuFrameTargets& targets, uint32_t x, uint32_t y);

// The world point (mm) drawn at the centre of pixel (x, y) at clip depth
// `depth` (a PickResult's), by inverting camera.h's viewProjection: the
// inverse of the pixel rule x_w = (x_ndc + 1) * width / 2 (same for y) and
// of the projection's depth mapping. nullopt for a depth outside [0, 1) or
// an invalid camera.
std::optional<Vec3d> unprojectPixel(const Camera& camera, double x, double y, double depth);

}  // namespace fibscope
