// Surfaces: the scene's analytic spheres (GpuScene::spheres), ray-cast per
// pixel into the surface target by sphere_surface.comp. The minimal surface
// pass, and the pattern every surface system follows: one shader writing
// nearer-wins SurfaceTexels, one stage, one line in the stage list.
#include <cmath>
#include <string>

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "shared/render_config.h"
#include "shared/surface_push.h"

namespace fibscope {
namespace {

class SphereStage final : public FrameStage {
 public:
  explicit SphereStage(const gpu::VulkanContext&) {}
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyBuffer(context, spheres_);
    gpu::destroyComputePipeline(context, pipeline_);
  }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override { return !frame.scene.spheres.empty(); }
  bool drawsSurfaces() const override { return true; }

  void check(const FrameContext& frame) const override {
    const std::vector<shader::SurfaceSphere>& spheres = frame.scene.spheres;
    if (spheres.size() > shader::kMaxSurfaceSpheres)
      throw Error("render: at most " + std::to_string(shader::kMaxSurfaceSpheres) + " spheres a frame, got " +
                  std::to_string(spheres.size()));
    for (const shader::SurfaceSphere& s : spheres)
      if (!(s.center_radius.w > 0.0f) || !std::isfinite(s.center_radius.x) || !std::isfinite(s.center_radius.y) ||
          !std::isfinite(s.center_radius.z) || !std::isfinite(s.center_radius.w))
        throw Error("render: a sphere needs a finite centre and a radius > 0 mm, got radius " +
                    std::to_string(s.center_radius.w));
  }

  void record(FrameContext& frame) override {
    const std::vector<shader::SurfaceSphere>& spheres = frame.scene.spheres;
    if (pipeline_.pipeline == VK_NULL_HANDLE)
      pipeline_ = gpu::createComputePipeline(frame.context, "sphere_surface.comp", sizeof(shader::SphereSurfacePush),
                                             gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
    if (!spheres_.buffer)
      spheres_ = gpu::createBuffer(frame.context, shader::kMaxSurfaceSpheres * sizeof(shader::SurfaceSphere),
                                   gpu::MemoryUse::DeviceLocal);
    // The spheres with the frame's commands: the previous frame's reads of
    // them first, the update before this frame's.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdUpdateBuffer(frame.cmd, spheres_.buffer, 0, spheres.size() * sizeof(shader::SurfaceSphere), spheres.data());
    gpu::recordBarrier(frame.cmd, gpu::kTransferToCompute);

    gpu::PassScope pass(frame.cmd, frame.timer, "spheres", gpu::kComputeToCompute);
    shader::SphereSurfacePush push{};
    push.camera = frame.targets.camera.address;
    push.spheres = spheres_.address;
    push.surface = frame.targets.surface.address;
    push.width = frame.targets.width;
    push.height = frame.targets.height;
    push.count = uint32_t(spheres.size());
    gpu::recordDispatch(frame.cmd, pipeline_, push, shader::pixelGroups(push.width), shader::pixelGroups(push.height));
  }

 private:
  gpu::ComputePipeline pipeline_;  // made at the first frame with spheres
  gpu::Buffer spheres_;            // kMaxSurfaceSpheres SurfaceSphere
};

}  // namespace

std::unique_ptr<FrameStage> makeSphereStage(const gpu::VulkanContext& context) {
  return std::make_unique<SphereStage>(context);
}

}  // namespace fibscope
