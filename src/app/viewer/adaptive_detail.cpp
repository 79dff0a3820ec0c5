#include "app/viewer/adaptive_detail.h"

#include <algorithm>

namespace fibscope {

bool sameView(const Camera& a, const Camera& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fov_y_deg == b.fov_y_deg;
}

bool drawCoarse(bool adaptive, const RenderSettings& settings, bool moving, double last_full_frame_ms) {
  return adaptive && settings.pipeline == RenderPipeline::Compute && moving && last_full_frame_ms > kSlowFrameMs;
}

RenderSettings coarseSettings(RenderSettings settings, float moving_lod_px) {
  settings.lod_pixels = std::max(settings.lod_pixels, moving_lod_px);
  settings.culling = CullingMode::Frustum;
  settings.ssao = false;
  return settings;
}

unsigned coarseDivisor(unsigned last_divisor, double last_coarse_frame_ms) {
  if (last_divisor == 4) return last_coarse_frame_ms > 0 && last_coarse_frame_ms < kSlowFrameMs / 4 ? 2 : 4;
  return last_coarse_frame_ms > kSlowFrameMs ? 4 : 2;
}

}  // namespace fibscope
