// The lines baseline's geometry: raw float vertices as line strips through
// the graphics pipeline (lines_pass.h), copied into the G-buffer.
#include <string>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/lines_pass.h"

namespace fibscope {
namespace {

class LinesStage final : public FrameStage {
 public:
  explicit LinesStage(const gpu::VulkanContext&) {}
  void destroy(const gpu::VulkanContext& context) override { destroyLinesPass(context, pass_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override { return frame.settings.pipeline == RenderPipeline::Lines; }
  // Made again at the next lines frame.
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override {
    releaseLinesAttachments(context, pass_);
  }
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    if (settings.pipeline == RenderPipeline::Lines) ensurePipeline(context);
  }

  void check(const FrameContext& frame) const override {
    if (!frame.scene.raw) throw Error("render: the lines pipeline needs the raw tractogram");
  }

  void record(FrameContext& frame) override {
    ensurePipeline(frame.context);
    ensureLinesAttachments(frame.context, pass_, frame.targets.width, frame.targets.height);
    frame.stats.segments_total = frame.scene.raw->segmentCount();
    // The copy into the G-buffer before the compute passes that read it.
    const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite};
    gpu::PassScope pass(frame.cmd, frame.timer, "lines", after);
    recordLines(frame.cmd, frame.context, pass_, *frame.scene.raw, frame.targets, frame.settings.line_width_px,
                frame.scene.kept_bits);
  }

 private:
  // Compute-only devices have no graphics queue and never need it.
  void ensurePipeline(const gpu::VulkanContext& context) {
    if (pass_.pipeline.pipeline == VK_NULL_HANDLE) pass_ = createLinesPass(context);
  }

  LinesPass pass_;
};

}  // namespace

std::unique_ptr<FrameStage> makeLinesStage(const gpu::VulkanContext& context) {
  return std::make_unique<LinesStage>(context);
}

}  // namespace fibscope
