// The compute pipeline's geometry (DESIGN.md section 6): the datasets'
// fiblets culled (frustum, LoD, two-phase occlusion), decoded and
// rasterised into the visibility buffer, then resolved into the G-buffer.
// The passes are in cull_passes.h and fiblet_passes.h; this stage
// keeps what spans frames (the cull lists, the two-phase history and the
// coverage buffer's previous frame, the tangent cache's size) and the
// statistics of the culled frame.
#include <string>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/fiblet_bounds.h"
#include "render/gpu/fiblet_passes.h"
#include "render/gpu/frame_stages.h"

namespace fibscope {
namespace {

class FibletStage final : public FrameStage {
 public:
  explicit FibletStage(const gpu::VulkanContext& context) {
    try {
      fiblet_passes_ = createFibletPasses(context);
      cull_passes_ = createCullPasses(context);
      bounds_pass_ = createFibletBoundsPass(context);
    } catch (...) {
      destroy(context);
      throw;
    }
  }

  void destroy(const gpu::VulkanContext& context) override {
    destroyCullBuffers(context, cull_buffers_);
    destroyFibletBoundsPass(context, bounds_pass_);
    destroyCullPasses(context, cull_passes_);
    destroyFibletPasses(context, fiblet_passes_);
  }

  // fiblet bounds, cull 1, raster 1, depth pyramid, cull 2, raster 2,
  // resolve (Coverage: fiblet bounds, coverage, cull, raster, resolve).
  uint32_t maxPasses() const override { return 7; }
  bool runs(const FrameContext& frame) const override {
    const bool compute = frame.settings.pipeline == RenderPipeline::Compute;
    // A frame of another pipeline breaks the coverage buffer's chain of
    // frames: the next compute frame must not re-project an older one.
    // (Asked every frame, before any stage records; the history is plain
    // state of this stage, hence mutable.)
    if (!compute) cull_buffers_.coverage.valid = false;
    return compute;
  }
  void resize(const gpu::VulkanContext&, uint32_t, uint32_t) override { tangent_cache_for_ = UINT64_MAX; }

  void check(const FrameContext& frame) const override {
    if (frame.scene.datasets.empty()) throw Error("render: the compute pipeline needs fiblets");
  }

  void record(FrameContext& frame) override {
    const SceneLayout& layout = frame.layout;
    const RenderSettings& settings = frame.settings;
    frame.stats.fiblets_total = layout.fiblets;
    // The rasters keep each drawn segment's tangent (at the global fiblet)
    // so the resolve need not decode again (when the scene's cache fits the
    // budget): sized when the scene's fiblet total changes, not per frame.
    // (The cache's contents never outlive a frame: every frame's rasters
    // write what its resolve reads.)
    if (tangent_cache_for_ != layout.fiblets) {
      prepareTangentCache(frame.context, frame.targets, layout.fiblets);
      tangent_cache_for_ = layout.fiblets;
    }
    // With a fiber filter even CullingMode::None goes through the cull
    // pass: it is where dropped fibers' fiblets are skipped.
    culled_ = (settings.culling != CullingMode::None || frame.scene.kept_bits != 0) && layout.fiblets > 0;
    const bool occlusion = settings.culling == CullingMode::TwoPhase || settings.culling == CullingMode::Coverage;
    if (occlusion) {
      // The occlusion test wants each dataset's exact spheres: computed in
      // this frame for a dataset that has none yet (frustum culling keeps
      // the record's looser bound; see dataset.h for why not at upload).
      bool missing = false;
      for (const SceneEntry& e : layout.entries) missing |= !e.dataset->fibletBoundsReady();
      if (missing) {
        // Each dataset's pass makes its spheres visible to the cull.
        gpu::PassScope pass(frame.cmd, frame.timer, "fiblet bounds", gpu::kNoBarrier);
        for (const SceneEntry& e : layout.entries) e.dataset->recordFibletBoundsOnce(frame.cmd, bounds_pass_);
      }
    }
    if (culled_) {
      // Cull passes, both rasters (and the pyramid and second phase for
      // TwoPhase) of every dataset; fiblets_drawn and fiblets_lod come from
      // collect().
      std::vector<uint32_t> fiblets;
      for (const SceneEntry& e : layout.entries) fiblets.push_back(e.dataset->block().fiblet_count);
      prepareCullBuffers(frame.context, cull_buffers_, fiblets, frame.targets.width, frame.targets.height,
                         settings.culling == CullingMode::Coverage);
      recordCulledRaster(frame.cmd, frame.context, cull_passes_, fiblet_passes_, layout, frame.targets, cull_buffers_,
                         CullFrame{settings.culling, settings.culling == CullingMode::None ? 0.0f : settings.lod_pixels,
                                   cullFocalPixels(frame.camera), frame.scene.kept_bits, frame.camera,
                                   settings.coverage_splat_px},
                         frame.timer);
    } else {
      gpu::PassScope pass(frame.cmd, frame.timer, "raster", gpu::kComputeToCompute);
      for (const SceneEntry& e : layout.entries)
        recordFibletRasterAll(frame.cmd, frame.context, fiblet_passes_, *e.dataset, frame.targets, e.fiblet_base);
      frame.stats.fiblets_drawn = layout.fiblets;
      cull_buffers_.history_valid = false;    // two-phase history skips this frame
      cull_buffers_.coverage.valid = false;  // and so does the coverage buffer's
    }
    gpu::PassScope pass(frame.cmd, frame.timer, "resolve", gpu::kComputeToCompute);
    recordFibletResolve(frame.cmd, fiblet_passes_, frame.scene_table, frame.targets);
  }

  void collect(const gpu::VulkanContext& context, FrameStats& stats) override {
    if (!culled_) return;
    collectCullStats(context, cull_buffers_, stats);
  }

 private:
  FibletPasses fiblet_passes_;
  CullPasses cull_passes_;
  FibletBoundsPass bounds_pass_;  // fills a dataset's spheres before its first occlusion cull
  // Lists, pyramid, the two-phase visible bits and the coverage history
  // (kept across frames; mutable: runs() drops the coverage history).
  mutable CullBuffers cull_buffers_;
  bool culled_ = false;           // the last frame was culled: collect() reads its counts
  // The scene fiblet total targets.tangents was prepared for (UINT64_MAX:
  // none yet).
  uint64_t tangent_cache_for_ = UINT64_MAX;
};

}  // namespace

std::unique_ptr<FrameStage> makeFibletStage(const gpu::VulkanContext& context) {
  return std::make_unique<FibletStage>(context);
}

}  // namespace fibscope
