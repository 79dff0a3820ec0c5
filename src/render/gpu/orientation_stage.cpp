// Last: the orientation overlay (orientation_overlay.comp,
// shared/orientation_overlay.h) stamped over the final colour, so nobody
// mistakes left for right. Which letter goes where is decided here, from
// the camera (render/orientation_labels.h).
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "render/orientation_labels.h"
#include "shared/orientation_overlay.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

class OrientationStage final : public FrameStage {
 public:
  explicit OrientationStage(const gpu::VulkanContext&) {}
  void destroy(const gpu::VulkanContext& context) override { gpu::destroyComputePipeline(context, pipeline_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override { return frame.settings.orientation_labels; }

  void record(FrameContext& frame) override {
    if (pipeline_.pipeline == VK_NULL_HANDLE)
      pipeline_ = gpu::createComputePipeline(frame.context, "orientation_overlay.comp",
                                             sizeof(shader::OrientationOverlayPush),
                                             gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
    const OrientationLabels labels = orientationLabels(frame.camera);
    const std::array<double, 16> view = viewMatrixD(frame.camera);
    shader::OrientationOverlayPush push{};
    // World axis a in view space: column a of the view's rotation.
    for (int a = 0; a < 3; ++a)
      push.axis[a] = {float(view[4 * a]), float(view[4 * a + 1]), float(view[4 * a + 2]), 0.0f};
    push.color = frame.targets.color.address;
    push.width = frame.targets.width;
    push.height = frame.targets.height;
    push.glyphs = uint32_t(labels.left) | uint32_t(labels.right) << 8 | uint32_t(labels.top) << 16 |
                  uint32_t(labels.bottom) << 24;
    push.scale = orientationScale(push.width, push.height);
    const uint32_t box = 26 * push.scale + 3;  // the triad's, the largest
    gpu::PassScope pass(frame.cmd, frame.timer, "orientation", gpu::kComputeToCompute);
    gpu::recordDispatch(frame.cmd, pipeline_, push, shader::pixelGroups(box), shader::pixelGroups(box),
                        shader::kOrientationBoxes);
  }

 private:
  gpu::ComputePipeline pipeline_;  // made at the first frame with labels
};

}  // namespace

std::unique_ptr<FrameStage> makeOrientationStage(const gpu::VulkanContext& context) {
  return std::make_unique<OrientationStage>(context);
}

}  // namespace fibscope
