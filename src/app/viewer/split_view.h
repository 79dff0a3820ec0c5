// The split view (issue 17: a bundled copy compared with its original):
// two models drawn side by side from one camera, each half by a frame
// renderer of its own (two-phase culling keeps a history per renderer) at
// half the width, then the two colour buffers copied into the full one.
//
// Each half's camera is the full camera at half the width, its eye twice as
// far from the target (same target, direction, up and vertical field of
// view; near and far moved back with it): a half then spans, at the target's
// depth, the width the whole window spans, so each model shows whole as the
// single view frames it, at half the scale. A half is exactly the centre half
// of the full-width frame the eye at twice the distance would give (x_half =
// x_full - width / 4, pixel for pixel). The orbit controller is not touched:
// turning the split off gives the same view back.
// Plain functions (STYLE.md rule 4).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.h"
#include "render/camera.h"

namespace fibscope {

// The left half's width (the right one has the rest).
inline uint32_t splitLeftWidth(uint32_t width) { return width / 2; }
// The camera of the left (`right` false) or right half of `camera`'s image.
inline constexpr double kSplitDistanceFactor = 2.0;
Camera splitHalfCamera(const Camera& camera, bool right);

// After both halves' frames were recorded (their shade passes wrote `left`
// and `right`, RGBA8, top row first, splitLeftWidth(width) and the rest
// wide, `height` rows): copies them side by side into `out` (width x height)
// and makes the copies visible to what reads `out` next (a copy into the
// presentation image, a download).
void recordSplitCompose(VkCommandBuffer cmd, const gpu::Buffer& left, const gpu::Buffer& right,
                        const gpu::Buffer& out, uint32_t width, uint32_t height);

}  // namespace fibscope
