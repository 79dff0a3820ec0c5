// The geometry and tessellation fiblet pipelines' geometry (the paper's
// section 4.5 comparisons; fiblet_graphics_pass.h): the scene's fiblets,
// culled by the compute pipeline's cull pass (frustum, and the fiber
// filter, which even CullingMode::None goes through, as in the compute
// stage) into lists that drive one indirect draw per dataset, or every
// fiblet drawn directly. No far-view LoD: these pipelines compare decoding
// every fiblet in a graphics stage, so the cull runs with LoD off.
// Two-phase occlusion culling draws last frame's visible fiblets, builds
// the depth pyramid from the G-buffer copy of that draw (these pipelines
// write no visibility buffer) and draws the rest that pass it. Coverage
// culling, which re-projects the compute raster's keys, is refused in one
// line.
#include <memory>
#include <string>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/fiblet_graphics_pass.h"
#include "render/gpu/frame_stages.h"

namespace fibscope {
namespace {

class FibletGraphicsStage final : public FrameStage {
 public:
  FibletGraphicsStage(const gpu::VulkanContext&, RenderPipeline kind) : kind_(kind) {}

  void destroy(const gpu::VulkanContext& context) override {
    destroyCullBuffers(context, cull_buffers_);
    destroyCullPasses(context, cull_passes_);
    destroyFibletGraphicsPass(context, pass_);
  }
  // cull 1, draw 1, depth pyramid, cull 2, draw 2.
  uint32_t maxPasses() const override { return 5; }
  bool runs(const FrameContext& frame) const override { return frame.settings.pipeline == kind_; }
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override {
    releaseLineAttachments(context, pass_.attachments);
  }
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    if (settings.pipeline == kind_) ensurePipelines(context);
  }

  void check(const FrameContext& frame) const override {
    checkFibletLinePipeline(kind_, frame.settings, !frame.scene.datasets.empty());
  }

  void record(FrameContext& frame) override {
    const SceneLayout& layout = frame.layout;
    const RenderSettings& settings = frame.settings;
    ensurePipelines(frame.context);
    ensureLineAttachments(frame.context, pass_.attachments, frame.targets.width, frame.targets.height);
    frame.stats.fiblets_total = layout.fiblets;
    culled_ = (settings.culling != CullingMode::None || frame.scene.kept_bits != 0) && layout.fiblets > 0;
    if (!culled_) {
      frame.stats.fiblets_drawn = layout.fiblets;
      draw(frame, nullptr, false, std::string(renderPipelineName(kind_)));
      return;
    }
    std::vector<uint32_t> fiblets;
    for (const SceneEntry& e : layout.entries) fiblets.push_back(e.dataset->block().fiblet_count);
    prepareCullBuffers(frame.context, cull_buffers_, fiblets, frame.targets.width, frame.targets.height);
    ensureFibletDrawArgs(frame.context, pass_, layout);
    const CullFrame cull{settings.culling, 0.0f, cullFocalPixels(frame.camera), frame.scene.kept_bits};
    const bool two_phase = settings.culling == CullingMode::TwoPhase;
    const std::string name(renderPipelineName(kind_));
    // Phase 1 (the only one without TwoPhase): last frame's visible
    // fiblets, as the compute stage's recordCulledRaster.
    cullAndDraw(frame, cull, two_phase ? 1 : 0, two_phase ? name + " 1" : name);
    if (!two_phase) return;
    {
      // The max-depth pyramid of what phase 1 drew, from the G-buffer copy
      // (the copy's writes before it: the draw pass's barrier).
      gpu::PassScope pass(frame.cmd, frame.timer, "depth pyramid", gpu::kComputeToCompute);
      recordDepthPyramid(frame.cmd, cull_passes_, frame.targets, cull_buffers_, 0, true);
    }
    // Phase 2: the rest against the pyramid, drawn over phase 1.
    cullAndDraw(frame, cull, 2, name + " 2");
  }

  void collect(const gpu::VulkanContext& context, FrameStats& stats) override {
    if (!culled_) return;
    collectCullStats(context, cull_buffers_, stats);
  }

 private:
  // Made at the first frame of this pipeline: devices without the stage
  // (or without graphics) never need it.
  void ensurePipelines(const gpu::VulkanContext& context) {
    if (pass_.pipeline.pipeline == VK_NULL_HANDLE) pass_ = createFibletGraphicsPass(context, kind_);
    if (cull_passes_.cull.pipeline == VK_NULL_HANDLE) cull_passes_ = createCullPasses(context);
  }

  // The draw pass (its G-buffer copy before the compute passes that read it).
  void draw(FrameContext& frame, const CullBuffers* culled, bool resume, const std::string& name) {
    const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite};
    gpu::PassScope pass(frame.cmd, frame.timer, name, after);
    recordFibletGraphics(frame.cmd, frame.context, pass_, frame.layout, frame.targets, culled,
                         frame.settings.line_width_px, resume);
  }

  // One cull phase (0: Frustum or None; 1, 2: TwoPhase), its draw, and its
  // counts for collect().
  void cullAndDraw(FrameContext& frame, const CullFrame& cull, uint32_t phase, const std::string& draw_name) {
    {
      // The lists' draws are this pass's successors: its barrier is
      // recordFibletDrawArgs's own.
      gpu::PassScope pass(frame.cmd, frame.timer, phase == 0 ? "cull" : "cull " + std::to_string(phase),
                          gpu::kNoBarrier);
      recordCullLists(frame.cmd, frame.context, cull_passes_, frame.layout, frame.targets, cull_buffers_, cull, phase);
      recordFibletDrawArgs(frame.cmd, pass_, cull_buffers_);
    }
    draw(frame, &cull_buffers_, phase == 2, draw_name);
    // The draws' reads of the lists and arguments before the count copies
    // (and the next resets); the cull's count writes made visible to them.
    gpu::memoryBarrier(frame.cmd,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT |
                           fibletGraphicsShaderStages(kind_),
                       VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
    recordCullListStats(frame.cmd, cull_buffers_, phase);
  }

  RenderPipeline kind_;
  FibletGraphicsPass pass_;
  CullPasses cull_passes_;
  CullBuffers cull_buffers_;
  bool culled_ = false;
};

}  // namespace

std::unique_ptr<FrameStage> makeGeometryStage(const gpu::VulkanContext& context) {
  return std::make_unique<FibletGraphicsStage>(context, RenderPipeline::Geometry);
}

std::unique_ptr<FrameStage> makeTessellationStage(const gpu::VulkanContext& context) {
  return std::make_unique<FibletGraphicsStage>(context, RenderPipeline::Tessellation);
}

}  // namespace fibscope
