#include "app/scene_filter.h"

#include <algorithm>
#include <cmath>

namespace fibscope {

SceneFilter::SceneFilter(const gpu::VulkanContext& context, const LoadedScene& scene, const FilterCriteria& criteria,
                         bool dim, int evaluations)
    : dim_(dim) {
  if (criteria.empty() && !criteria.distance_zone) return;
  const FiberFilter filter(criteria, scene.step_size_mm);
  const shader::FibletDataset& block = scene.fiblets.block();
  const FilterFibletSource source{scene.fiblets.blockAddress(), block.fiblet_count, block.fiber_count, 0,
                                  scene.fiblets.fiberLength().address};
  fiblets_ = std::make_unique<GpuFiberFilter>(context);
  for (int i = 0; i < std::max(evaluations, 1); ++i) {
    fiblets_->invalidate();  // the same criteria again: run the passes, as a changed sphere does
    fiblets_->update(filter, std::span(&source, 1), block.fiber_count, scene.fiber_scalars);
    gpu_ms_.push_back(fiblets_->lastGpuMilliseconds());
  }
  if (scene.has_raw) {
    // The raw vertices are the same fibers in the same order: the
    // dataset's lengths are theirs.
    raw_ = std::make_unique<GpuFiberFilter>(context);
    raw_->update(filter, FilterRawSource{scene.raw.blockAddress(), scene.raw.streamlineCount(), scene.raw.pointCount(),
                                         scene.fiblets.fiberLength().address},
                 scene.fiber_scalars);
    raw_gpu_ms_ = raw_->lastGpuMilliseconds();
  }
}

double SceneFilter::gpuMilliseconds() const {
  if (gpu_ms_.empty()) return 0;
  std::vector<double> sorted = gpu_ms_;
  std::sort(sorted.begin(), sorted.end());
  return sorted[sorted.size() / 2];
}

void SceneFilter::apply(GpuScene& scene, RenderPipeline pipeline) const {
  if (!active()) return;
  const GpuFiberFilter& f = drawsFiblets(pipeline) || !raw_ ? *fiblets_ : *raw_;
  if (f.zoneDistances() != 0) scene.fiber_scalars = f.zoneDistances();
  if (dim_) {
    // Kept fibers as the selection: the rest dimmed. (Nothing kept: an
    // empty selection would dim nothing, so the words are passed anyway.)
    scene.selection_bits = f.keptBits();
    return;
  }
  scene.kept_bits = f.keptBits();
  scene.kept_point_bits = f.keptPointBits();
}

bool SceneFilter::distanceRange(float& lo, float& hi) const {
  if (!fiblets_ || fiblets_->zoneDistances() == 0) return false;
  bool any = false;
  for (float d : fiblets_->zoneDistanceValues()) {
    if (!std::isfinite(d)) continue;
    lo = any ? std::min(lo, d) : d;
    hi = any ? std::max(hi, d) : d;
    any = true;
  }
  return any;
}

std::vector<uint32_t> SceneFilter::keptFibers() const {
  return fiblets_ ? fiblets_->keptFibers() : std::vector<uint32_t>();
}

}  // namespace fibscope
