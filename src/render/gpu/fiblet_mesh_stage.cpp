// The mesh fiblet pipelines' geometry (fiblet_mesh_pass.h): the task
// shader culls as the compute stage does, in the same modes, with the same
// buffers (cull_passes.h: the two-phase visible bits and history, the depth
// pyramid, the counters the statistics copy):
//   None, no filter:  every fiblet drawn (no test);
//   None + filter:    the filter's fibers (kCullKeptOnly);
//   Frustum:          dilated frustum and far-view LoD;
//   TwoPhase:         phase 1 draws last frame's visible fiblets, the depth
//                     pyramid is built from the G-buffer copy of that draw
//                     (as the geometry pipeline's: no visibility buffer),
//                     phase 2 tests the rest against it and draws over
//                     phase 1.
// Coverage culling re-projects the compute raster's keys: refused in one
// line, as the geometry pipeline refuses it. So is a device without
// VK_EXT_mesh_shader, before anything is created or recorded.
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/fiblet_mesh_pass.h"
#include "render/gpu/frame_stages.h"
#include "shared/cull_push.h"

namespace fibscope {
namespace {

class FibletMeshStage final : public FrameStage {
 public:
  FibletMeshStage(const gpu::VulkanContext&, RenderPipeline kind) : kind_(kind) {}

  void destroy(const gpu::VulkanContext& context) override {
    destroyCullBuffers(context, cull_buffers_);
    destroyCullPasses(context, cull_passes_);
    destroyFibletMeshPass(context, pass_);
  }
  // draw 1, depth pyramid, draw 2.
  uint32_t maxPasses() const override { return 3; }
  bool runs(const FrameContext& frame) const override { return frame.settings.pipeline == kind_; }
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override {
    releaseLineAttachments(context, pass_.attachments);
  }
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    if (settings.pipeline == kind_) ensurePipelines(context);
  }

  void check(const FrameContext& frame) const override {
    if (const std::string why = fibletMeshRefusal(frame.context, kind_); !why.empty()) throw Error(why);
    checkFibletLinePipeline(kind_, frame.settings, !frame.scene.datasets.empty());
  }

  void record(FrameContext& frame) override {
    const SceneLayout& layout = frame.layout;
    const RenderSettings& settings = frame.settings;
    ensurePipelines(frame.context);
    ensureLineAttachments(frame.context, pass_.attachments, frame.targets.width, frame.targets.height);
    frame.stats.fiblets_total = layout.fiblets;
    // The earlier compute passes' writes the task shader reads: the mesh
    // cuts' tiles (their stage's barrier names compute, vertex and
    // fragment readers only) and the fiber filter's bits.
    gpu::memoryBarrier(frame.cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                       VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       kFibletMeshShaderStages, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    const std::string name(renderPipelineName(kind_));
    culled_ = (settings.culling != CullingMode::None || frame.scene.kept_bits != 0) && layout.fiblets > 0;
    if (!culled_) {
      frame.stats.fiblets_drawn = layout.fiblets;
      draw(frame, FibletMeshCull{}, 0, name);
      return;
    }
    std::vector<uint32_t> fiblets;
    for (const SceneEntry& e : layout.entries) fiblets.push_back(e.dataset->block().fiblet_count);
    prepareCullBuffers(frame.context, cull_buffers_, fiblets, frame.targets.width, frame.targets.height);
    FibletMeshCull cull;
    cull.draw_all = false;
    cull.lod_pixels = settings.lod_pixels;
    cull.focal_px = cullFocalPixels(frame.camera);
    cull.kept_bits = frame.scene.kept_bits;
    cull.buffers = &cull_buffers_;
    if (settings.culling != CullingMode::TwoPhase) {
      cull.mode = settings.culling == CullingMode::Frustum ? shader::kCullFrustum : shader::kCullKeptOnly;
      draw(frame, cull, 0, name);
      return;
    }
    cull.mode = shader::kCullPhase1;
    draw(frame, cull, 1, name + " 1");
    {
      // The max-depth pyramid of what phase 1 drew, from the G-buffer copy
      // (after the copy: the draw pass's barrier), read by phase 2's task
      // shader.
      const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                   VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT};
      gpu::PassScope pass(frame.cmd, frame.timer, "depth pyramid", after);
      recordDepthPyramid(frame.cmd, cull_passes_, frame.targets, cull_buffers_, 0, true);
    }
    cull.mode = shader::kCullPhase2;
    draw(frame, cull, 2, name + " 2");
  }

  void collect(const gpu::VulkanContext& context, FrameStats& stats) override {
    if (!culled_) return;
    collectCullStats(context, cull_buffers_, stats);
  }

 private:
  // Made at the first frame of this pipeline: devices without mesh shaders
  // never need it (check() refuses them first).
  void ensurePipelines(const gpu::VulkanContext& context) {
    if (pass_.pipeline.pipeline == VK_NULL_HANDLE) pass_ = createFibletMeshPass(context, kind_);
    if (cull_passes_.cull.pipeline == VK_NULL_HANDLE) cull_passes_ = createCullPasses(context);
  }

  // One draw pass (phase 0: the only one; 1, 2: TwoPhase's), its counters
  // reset before and copied after when culled, and the G-buffer copy
  // before the compute passes that read it.
  void draw(FrameContext& frame, const FibletMeshCull& cull, uint32_t phase, const std::string& name) {
    {
      const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite};
      gpu::PassScope pass(frame.cmd, frame.timer, name, after);
      if (!cull.draw_all)
        recordCullCountersReset(frame.cmd, cull_buffers_, frame.layout, phase, VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT);
      recordFibletMesh(frame.cmd, frame.context, pass_, frame.layout, frame.targets, cull,
                       frame.settings.line_width_px, phase == 2);
    }
    if (cull.draw_all) return;
    // The task shader's counts (and phase 2's visible bits) before the
    // count copies, the next phase's resets and the next frame's reads.
    gpu::memoryBarrier(frame.cmd, VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_TRANSFER_BIT | VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT,
                       VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT | gpu::kStorageReadWrite);
    recordCullListStats(frame.cmd, cull_buffers_, phase);
    markCullHistory(cull_buffers_, frame.layout, phase);
  }

  RenderPipeline kind_;
  FibletMeshPass pass_;
  CullPasses cull_passes_;
  CullBuffers cull_buffers_;
  bool culled_ = false;
};

}  // namespace

std::unique_ptr<FrameStage> makeMeshStage(const gpu::VulkanContext& context) {
  return std::make_unique<FibletMeshStage>(context, RenderPipeline::Mesh);
}

std::unique_ptr<FrameStage> makeMeshSerialStage(const gpu::VulkanContext& context) {
  return std::make_unique<FibletMeshStage>(context, RenderPipeline::MeshSerial);
}

}  // namespace fibscope
