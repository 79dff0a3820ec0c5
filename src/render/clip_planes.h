// The clip planes of a frame (RenderSettings::clip_planes and slab): what
// the camera block carries (shared/camera.h) and the CPU reference
// rasteriser clips with.
#pragma once

#include <array>
#include <vector>

#include "render/camera.h"
#include "render/render_settings.h"

namespace fibscope {

using PlaneEq = std::array<double, 4>;  // (n, d): keeps n.p + d >= 0

// The plane through `point` keeping the side `normal` points to (normal
// made unit). Throws Error for a zero or non-finite normal or point.
PlaneEq planeThrough(const std::array<double, 3>& point, const std::array<double, 3>& normal);

// The user's planes, then the slab's two (when slab_mm > 0): at most
// shader::kMaxFrameClipPlanes. Throws Error for more than
// shader::kMaxClipPlanes user planes, a plane with a zero normal or a
// non-finite value, or a negative slab.
std::vector<PlaneEq> frameClipPlanes(const RenderSettings& settings, const Camera& camera);

// Whether world point p lies on the kept side of every plane.
bool keptByPlanes(const std::vector<PlaneEq>& planes, const std::array<double, 3>& p);

}  // namespace fibscope
