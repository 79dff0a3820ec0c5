// The fiber filter of what `render` and `bench` draw: the criteria of the
// command line evaluated on the GPU once (select/gpu/gpu_fiber_filter.h),
// on the fiblets and, when the baselines' raw vertices are uploaded too,
// on those, and applied to each frame's GpuScene: dropped fibers hidden
// (not drawn), or with --dim-dropped drawn dimmed, the kept ones
// highlighted as a selection.
#pragma once

#include <memory>
#include <vector>

#include "app/render_scene.h"
#include "render/gpu/scene.h"
#include "render/render_settings.h"
#include "select/fiber_filter.h"
#include "select/gpu/gpu_fiber_filter.h"

namespace fibscope {

class SceneFilter {
 public:
  SceneFilter() = default;
  // Evaluates `criteria` (nothing when empty) with the margin of the
  // scene's step size; its scalar ranges read scene.fiber_scalars (loaded
  // with SceneOptions::fiber_scalars = the same ranges). Throws Error as
  // GpuFiberFilter::update does. `evaluations` > 1 evaluates the fiblets'
  // filter that many times (each re-tests every criterion, as a changed
  // sphere does), for a median time: the first evaluation of a run also
  // pays for cold caches and a GPU's clock ramp.
  SceneFilter(const gpu::VulkanContext& context, const LoadedScene& scene, const FilterCriteria& criteria, bool dim,
              int evaluations = 1);

  bool active() const { return fiblets_ != nullptr; }
  // Sets what a frame of `pipeline` reads: scene.kept_bits (and
  // kept_point_bits) when hiding, scene.selection_bits when dimming; with
  // a distance zone, scene.fiber_scalars = each fiber's distance to it (mm),
  // what ColorMode::Scalar then shows.
  void apply(GpuScene& scene, RenderPipeline pipeline) const;
  // With a distance zone: the smallest and largest finite distance (for
  // the colormap's range); false without one.
  bool distanceRange(float& lo, float& hi) const;
  uint64_t kept() const { return fiblets_ ? fiblets_->keptCount() : 0; }
  // The kept fibers' indices, ascending (downloaded); empty when inactive.
  std::vector<uint32_t> keptFibers() const;
  uint64_t fibers() const { return fiblets_ ? fiblets_->fiberCount() : 0; }
  // GPU time of one evaluation on the fiblets: the median of the evaluations.
  double gpuMilliseconds() const;
  // Each evaluation's GPU time on the fiblets, in order.
  const std::vector<double>& gpuMillisecondsEach() const { return gpu_ms_; }
  // GPU time of the evaluation on the raw vertices (0 without them).
  double rawGpuMilliseconds() const { return raw_gpu_ms_; }

 private:
  std::unique_ptr<GpuFiberFilter> fiblets_, raw_;
  bool dim_ = false;
  std::vector<double> gpu_ms_;
  double raw_gpu_ms_ = 0;
};

}  // namespace fibscope
