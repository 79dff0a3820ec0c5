// Shading, last and optional: FXAA (fxaa.comp, Lottes' FXAA 3.11 quality
// preset as shared/shade_push.h describes) of the shaded (and, when they
// run, post-processed) image, always read from `shaded`, into the frame's
// colour (shading_stages.h: ShadeTarget).
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/shading_stages.h"
#include "shared/render_config.h"
#include "shared/shade_push.h"

namespace fibscope {
namespace {

// FXAA 3.11's quality-preset defaults: contrast below 1/8 of the local
// maximum luma (or below 1/16 absolute, for dark regions) is no edge;
// sub-pixel blending at three quarters.
constexpr float kFxaaEdgeThreshold = 0.125f;
constexpr float kFxaaEdgeThresholdMin = 0.0625f;
constexpr float kFxaaSubpix = 0.75f;

class FxaaStage final : public FrameStage {
 public:
  explicit FxaaStage(const gpu::VulkanContext& context) : pass_(createFxaaPass(context)) {}
  void destroy(const gpu::VulkanContext& context) override { destroyFxaaPass(context, pass_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override { return fxaaRuns(frame.settings); }
  void record(FrameContext& frame) override {
    gpu::PassScope pass(frame.cmd, frame.timer, "fxaa", gpu::kComputeToCompute);
    recordFxaa(frame.cmd, pass_, frame.targets.shaded, frame.targets.color, frame.targets.width,
               frame.targets.height);
  }

 private:
  FxaaPass pass_;
};

}  // namespace

FxaaPass createFxaaPass(const gpu::VulkanContext& context) {
  return {gpu::createComputePipeline(context, "fxaa.comp", sizeof(shader::FxaaPush),
                                     gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize})};
}

void destroyFxaaPass(const gpu::VulkanContext& context, FxaaPass& pass) {
  gpu::destroyComputePipeline(context, pass.pipeline);
}

void recordFxaa(VkCommandBuffer cmd, const FxaaPass& pass, const gpu::Buffer& input, const gpu::Buffer& output,
                uint32_t width, uint32_t height) {
  shader::FxaaPush push{};
  push.color_in = input.address;
  push.color_out = output.address;
  push.width = width;
  push.height = height;
  push.edge_threshold = kFxaaEdgeThreshold;
  push.edge_threshold_min = kFxaaEdgeThresholdMin;
  push.subpix = kFxaaSubpix;
  gpu::recordDispatch(cmd, pass.pipeline, push, shader::pixelGroups(width), shader::pixelGroups(height));
}

std::unique_ptr<FrameStage> makeFxaaStage(const gpu::VulkanContext& context) {
  return std::make_unique<FxaaStage>(context);
}

}  // namespace fibscope
