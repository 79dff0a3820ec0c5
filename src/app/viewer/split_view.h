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
//
// The camera was framed on the models visible when the last one was added:
// a bundled copy comes in alone (its original hidden), and is smaller than
// its original, which would then be cut at the edges of its half. So the
// eye goes back farther by the ratio of the two models' union to the framed
// box (splitDistanceFactor), and both halves keep one scale.
// Plain functions (STYLE.md rule 4).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.h"
#include "render/camera.h"

namespace fibscope {

// The left half's width (the right one has the rest).
inline uint32_t splitLeftWidth(uint32_t width) { return width / 2; }
inline constexpr double kSplitDistanceFactor = 2.0;
// kSplitDistanceFactor times the ratio of the bounding spheres (half box
// diagonals) of `shown` (the union of the two models) and of `framed`,
// when that is above 1. Diagonals, not a snug fit along the view direction, so that
// the scale stays put while the user orbits.
double splitDistanceFactor(const Bounds& framed, const Bounds& shown);
// The camera of the left (`right` false) or right half of `camera`'s
// image, its eye `distance_factor` times as far from the target; near and
// far enclose both what the full camera's did and the box `shown` (the
// union of the two models).
Camera splitHalfCamera(const Camera& camera, bool right, double distance_factor, const Bounds& shown);

// After both halves' frames were recorded (their shade passes wrote `left`
// and `right`, RGBA8, top row first, splitLeftWidth(width) and the rest
// wide, `height` rows): copies them side by side into `out` (width x height)
// and makes the copies visible to what reads `out` next (a copy into the
// presentation image, a download).
void recordSplitCompose(VkCommandBuffer cmd, const gpu::Buffer& left, const gpu::Buffer& right,
                        const gpu::Buffer& out, uint32_t width, uint32_t height);

}  // namespace fibscope
