// The raw-compute baseline's geometry: every raw segment through the
// compute raster, no culling, then its resolve (raw_passes.h).
#include <string>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/raw_passes.h"

namespace fibscope {
namespace {

class RawComputeStage final : public FrameStage {
 public:
  explicit RawComputeStage(const gpu::VulkanContext& context) : passes_(createRawPasses(context)) {}
  void destroy(const gpu::VulkanContext& context) override { destroyRawPasses(context, passes_); }
  uint32_t maxPasses() const override { return 2; }
  bool runs(const FrameContext& frame) const override {
    return frame.settings.pipeline == RenderPipeline::RawCompute;
  }

  void check(const FrameContext& frame) const override {
    if (!frame.scene.raw) throw Error("render: the raw-compute pipeline needs the raw tractogram");
  }

  void record(FrameContext& frame) override {
    frame.stats.segments_total = frame.scene.raw->segmentCount();
    {
      gpu::PassScope pass(frame.cmd, frame.timer, "raster", gpu::kComputeToCompute);
      recordRawRaster(frame.cmd, frame.context, passes_, *frame.scene.raw, frame.targets, frame.scene.kept_point_bits);
    }
    gpu::PassScope pass(frame.cmd, frame.timer, "resolve", gpu::kComputeToCompute);
    recordRawResolve(frame.cmd, passes_, *frame.scene.raw, frame.targets);
  }

 private:
  RawPasses passes_;
};

}  // namespace

std::unique_ptr<FrameStage> makeRawComputeStage(const gpu::VulkanContext& context) {
  return std::make_unique<RawComputeStage>(context);
}

}  // namespace fibscope
