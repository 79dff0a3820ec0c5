// Adaptive detail: where a full-detail frame is slow (a CPU device such as
// lavapipe, or a model far larger than the GPU draws at interactive rates),
// frames drawn while the camera moves trade detail for time, so orbiting
// answers the mouse; the first frame after the camera stops has the full
// detail again. Pure functions: no Vulkan, no ImGui.
#pragma once

#include "render/camera.h"
#include "render/render_settings.h"

namespace fibscope {

// A full-detail frame slower than this (submission to completion, ms) makes
// the moves coarse.
inline constexpr double kSlowFrameMs = 100.0;

// Whether two cameras show the same view (same eye, target, up and field
// of view; the image size is not compared).
bool sameView(const Camera& a, const Camera& b);

// Whether this frame is drawn coarse: adaptive detail on, the compute
// pipeline (the baselines have no LoD), the camera moving, and the last
// full-detail frame slower than kSlowFrameMs.
bool drawCoarse(bool adaptive, const RenderSettings& settings, bool moving, double last_full_frame_ms);

// The settings of a coarse frame: fiblets projected smaller than
// `moving_lod_px` (at least the settings' own LoD size) drawn as one segment,
// frustum culling only (one cull pass: the LoD lives in the cull; an
// occlusion pass has little left to cull), no ambient occlusion (two
// full-screen passes and a blur, a large share of a coarse frame on a CPU).
RenderSettings coarseSettings(RenderSettings settings, float moving_lod_px);

// How much smaller than the window a coarse frame is drawn (2 or 4 per
// side), from the last coarse frame's divisor and time (submission to
// completion, ms; 0 before any): 2 to start; 4 once a half-resolution frame
// is still slower than kSlowFrameMs (a coarse frame's raster is bound by its
// pixels, so a quarter of them is about four times faster); back to 2 when
// a quarter-resolution frame takes under a quarter of kSlowFrameMs, so the
// two never alternate.
unsigned coarseDivisor(unsigned last_divisor, double last_coarse_frame_ms);

}  // namespace fibscope
