// The attachments every graphics pipeline that draws the G-buffer's lines
// uses (the lines baseline, the geometry and tessellation fiblet
// pipelines): an R32G32B32A32_UINT colour attachment that holds exactly the
// G-buffer texel's four words (shared/gbuffer.h) and a D32 depth attachment
// (LESS), cleared to the empty texel and depth 1, then copied into
// GpuFrameTargets::gbuffer so shading reads the same layout whatever
// pipeline drew the frame.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/image.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/frame_targets.h"

namespace fibscope {

inline constexpr VkFormat kLineColorFormat = VK_FORMAT_R32G32B32A32_UINT;
inline constexpr VkFormat kLineDepthFormat = VK_FORMAT_D32_SFLOAT;

struct LineAttachments {
  gpu::Image color;  // kLineColorFormat, the frame's size (none until the first frame)
  gpu::Image depth;  // kLineDepthFormat
};

// Attachments of width x height; replaces others of another size (waits
// for the device to be idle first). Throws Error when memory runs out.
void ensureLineAttachments(const gpu::VulkanContext& context, LineAttachments& a, uint32_t width, uint32_t height);
// Frees the attachments (the device must not be using them).
void releaseLineAttachments(const gpu::VulkanContext& context, LineAttachments& a);

// Begins dynamic rendering into the attachments, cleared to the empty
// texel (depth 1.0, no fiber, segment and tangent 0) and depth 1, after the
// previous frame's copy out of the colour attachment.
void beginLineAttachments(VkCommandBuffer cmd, LineAttachments& a);
// Begins rendering that keeps what endLineAttachmentsIntoGBuffer left (the
// second phase of two-phase culling draws over the first).
void resumeLineAttachments(VkCommandBuffer cmd, LineAttachments& a);
// Ends rendering and copies the colour attachment into frame.gbuffer
// (written at the TRANSFER stage when this returns).
void endLineAttachmentsIntoGBuffer(VkCommandBuffer cmd, LineAttachments& a, const GpuFrameTargets& frame);

}  // namespace fibscope
