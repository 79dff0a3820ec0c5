// The geometry and tessellation fiblet pipelines' geometry (the paper's
// section 4.5 comparisons; fiblet_graphics_pass.h): the scene's fiblets,
// culled by the compute pipeline's cull pass (frustum, and the fiber
// filter, which even CullingMode::None goes through, as in the compute
// stage) into lists that drive one indirect draw per dataset, or every
// fiblet drawn directly. No far-view LoD: these pipelines compare decoding
// every fiblet in a graphics stage, so the cull runs with LoD off.
// Two-phase occlusion culling is refused in one line: its depth pyramid is
// built from the compute rasters' visibility buffer, which these pipelines
// do not write.
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
  // cull, draw.
  uint32_t maxPasses() const override { return 2; }
  bool runs(const FrameContext& frame) const override { return frame.settings.pipeline == kind_; }
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override {
    releaseLineAttachments(context, pass_.attachments);
  }
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    if (settings.pipeline == kind_) ensurePipelines(context);
  }

  void check(const FrameContext& frame) const override {
    const std::string name(renderPipelineName(kind_));
    if (frame.scene.datasets.empty()) throw Error("render: the " + name + " pipeline needs fiblets");
    if (frame.settings.culling == CullingMode::TwoPhase)
      throw Error("render: the " + name +
                  " pipeline culls with none or frustum (two-phase culling builds its depth pyramid from the "
                  "compute rasters; use --culling frustum)");
  }

  void record(FrameContext& frame) override {
    const SceneLayout& layout = frame.layout;
    const RenderSettings& settings = frame.settings;
    ensurePipelines(frame.context);
    ensureLineAttachments(frame.context, pass_.attachments, frame.targets.width, frame.targets.height);
    frame.stats.fiblets_total = layout.fiblets;
    culled_ = (settings.culling != CullingMode::None || frame.scene.kept_bits != 0) && layout.fiblets > 0;
    const VkPipelineStageFlags2 shaders = fibletGraphicsShaderStages(kind_);
    if (culled_) {
      std::vector<uint32_t> fiblets;
      for (const SceneEntry& e : layout.entries) fiblets.push_back(e.dataset->block().fiblet_count);
      prepareCullBuffers(frame.context, cull_buffers_, fiblets, frame.targets.width, frame.targets.height);
      // The lists' draws are this pass's successors: its barrier is
      // recordFibletDrawArgs's own.
      gpu::PassScope pass(frame.cmd, frame.timer, "cull", gpu::kNoBarrier);
      recordCullLists(frame.cmd, frame.context, cull_passes_, layout, frame.targets, cull_buffers_,
                      CullFrame{settings.culling, 0.0f, cullFocalPixels(frame.camera), frame.scene.kept_bits});
      recordFibletDrawArgs(frame.cmd, pass_, cull_buffers_);
    } else {
      frame.stats.fiblets_drawn = layout.fiblets;
    }
    {
      // The copy into the G-buffer before the compute passes that read it.
      const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite};
      gpu::PassScope pass(frame.cmd, frame.timer, std::string(renderPipelineName(kind_)), after);
      recordFibletGraphics(frame.cmd, frame.context, pass_, layout, frame.targets, culled_ ? &cull_buffers_ : nullptr,
                           settings.line_width_px);
    }
    if (culled_) {
      // The draws' reads of the lists and arguments before the count copies
      // (and the next frame's resets).
      // The cull's count writes, made visible to the copies.
      gpu::memoryBarrier(frame.cmd,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | shaders,
                         VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                         VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
      recordCullListStats(frame.cmd, cull_buffers_);
    }
  }

  void collect(const gpu::VulkanContext& context, FrameStats& stats) override {
    if (!culled_) return;
    const CullStats cull = readCullStats(context, cull_buffers_);
    stats.fiblets_drawn = cull.full();
    stats.fiblets_lod = cull.lod();
  }

 private:
  // Made at the first frame of this pipeline: devices without the stage
  // (or without graphics) never need it.
  void ensurePipelines(const gpu::VulkanContext& context) {
    if (pass_.pipeline.pipeline == VK_NULL_HANDLE) pass_ = createFibletGraphicsPass(context, kind_);
    if (cull_passes_.cull.pipeline == VK_NULL_HANDLE) cull_passes_ = createCullPasses(context);
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
