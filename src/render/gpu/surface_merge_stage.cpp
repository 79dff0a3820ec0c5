// The surface target into the G-buffer by depth (surface_merge.comp): after
// the geometry stage whichever pipeline drew the lines, so surfaces and
// lines occlude each other both ways and every later pass (shading, SSAO,
// picking) reads one G-buffer.
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "shared/render_config.h"
#include "shared/surface_push.h"

namespace fibscope {
namespace {

class SurfaceMergeStage final : public FrameStage {
 public:
  explicit SurfaceMergeStage(const gpu::VulkanContext&) {}
  void destroy(const gpu::VulkanContext& context) override { gpu::destroyComputePipeline(context, pipeline_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override { return frame.surfaces; }

  void record(FrameContext& frame) override {
    if (pipeline_.pipeline == VK_NULL_HANDLE)
      pipeline_ = gpu::createComputePipeline(frame.context, "surface_merge.comp", sizeof(shader::SurfaceMergePush),
                                             gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
    gpu::PassScope pass(frame.cmd, frame.timer, "surface merge", gpu::kComputeToCompute);
    shader::SurfaceMergePush push{};
    push.surface = frame.targets.surface.address;
    push.gbuffer = frame.targets.gbuffer.address;
    push.width = frame.targets.width;
    push.height = frame.targets.height;
    gpu::recordDispatch(frame.cmd, pipeline_, push, shader::pixelGroups(push.width), shader::pixelGroups(push.height));
  }

 private:
  gpu::ComputePipeline pipeline_;  // made at the first frame with surfaces
};

}  // namespace

std::unique_ptr<FrameStage> makeSurfaceMergeStage(const gpu::VulkanContext& context) {
  return std::make_unique<SurfaceMergeStage>(context);
}

}  // namespace fibscope
