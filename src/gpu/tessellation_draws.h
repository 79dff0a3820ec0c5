// Draws of one-vertex tessellation patches, split where the device needs
// it: lavapipe (Mesa 22.3) hands the control and evaluation stages another
// patch's inputs in draws of many patches (measured on the fiblet
// tessellation pipeline: a 400-fiber phantom drew half its pixels; in
// draws of 64 patches it matches the lines baseline, and 25 times faster;
// render/gpu/fiblet_graphics_pass.h), so on CPU devices a draw covers at
// most kCpuTessellationPatchesPerDraw patches. Shared by the fiblet
// tessellation pipeline and the tessellated spline tubes.
#pragma once

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdint>

#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

inline constexpr uint32_t kCpuTessellationPatchesPerDraw = 64;

// The most patches one draw may hold on `context`'s device; 0: no cap.
inline uint32_t tessellationPatchesPerDraw(const VulkanContext& context) {
  return context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? kCpuTessellationPatchesPerDraw : 0u;
}

// Patches first .. first + count - 1 (one vertex each: gl_VertexIndex
// names the patch) in draws of at most `per_draw` (0: one draw), with the
// pipeline and its push constants already bound.
inline void recordPatchDraws(VkCommandBuffer cmd, uint32_t first, uint32_t count, uint32_t per_draw) {
  const uint32_t chunk = per_draw == 0 ? count : per_draw;
  for (uint32_t done = 0; done < count; done += chunk)
    vkCmdDraw(cmd, std::min(chunk, count - done), 1, first + done, 0);
}

}  // namespace fibscope::gpu
