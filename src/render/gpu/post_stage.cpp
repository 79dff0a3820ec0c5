// Shading, optional: post effects (post_effects.comp; FiberVisualizer
// section 12, formulas in shared/post_push.h) of the shaded image.
//
// Its place in the frame: after shade, which has already multiplied in the
// ambient occlusion (the paper applies its post-processing to the lit,
// occluded image, and in the order flattening, contrast, brightness,
// saturation, sharpening, which the shader keeps), and before FXAA: FXAA
// finds edges by luma contrast, so it has to see the image as it will be
// shown (contrast and sharpening change which edges pass its threshold, and
// flattening makes new ones), and sharpening after FXAA would bring back
// the stair steps FXAA smoothed. The orientation overlay stays last.
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/shading_stages.h"
#include "shared/post_push.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

class PostStage final : public FrameStage {
 public:
  explicit PostStage(const gpu::VulkanContext& context) : pass_(createPostPass(context)) {}
  void destroy(const gpu::VulkanContext& context) override { destroyPostPass(context, pass_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override { return postEffectsRun(frame.settings); }
  void record(FrameContext& frame) override {
    const GpuFrameTargets& t = frame.targets;
    auto buffer = [&](ShadeTarget target) -> const gpu::Buffer& {
      return target == ShadeTarget::Color ? t.color : t.shaded;
    };
    gpu::PassScope pass(frame.cmd, frame.timer, "post", gpu::kComputeToCompute);
    recordPostEffects(frame.cmd, pass_, buffer(postInput(frame.settings)), buffer(postOutput(frame.settings)),
                      t.width, t.height, frame.settings);
  }

 private:
  PostPass pass_;
};

}  // namespace

bool postEffectsRun(const RenderSettings& s) {
  return s.flatten_levels >= 2 || s.contrast != 1.0f || s.brightness != 0.0f || s.saturation != 1.0f ||
         s.sharpen != 0.0f;
}

ShadeTarget shadeTarget(const RenderSettings& s) {
  const bool post = postEffectsRun(s), fxaa = fxaaRuns(s);
  return post != fxaa ? ShadeTarget::Shaded : ShadeTarget::Color;
}

ShadeTarget postInput(const RenderSettings& s) { return shadeTarget(s); }

ShadeTarget postOutput(const RenderSettings& s) {
  return fxaaRuns(s) ? ShadeTarget::Shaded : ShadeTarget::Color;  // FXAA reads shaded into color
}

PostPass createPostPass(const gpu::VulkanContext& context) {
  PostPass pass;
  try {
    for (uint32_t sharpen : {0u, 1u}) {
      const uint32_t specialization[] = {sharpen};  // kPostSpecSharpen
      pass.pipelines[sharpen] =
          gpu::createComputePipeline(context, "post_effects.comp", sizeof(shader::PostPush),
                                     gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize},
                                     specialization);
    }
  } catch (...) {
    destroyPostPass(context, pass);
    throw;
  }
  return pass;
}

void destroyPostPass(const gpu::VulkanContext& context, PostPass& pass) {
  for (gpu::ComputePipeline& p : pass.pipelines) gpu::destroyComputePipeline(context, p);
}

void recordPostEffects(VkCommandBuffer cmd, const PostPass& pass, const gpu::Buffer& input,
                       const gpu::Buffer& output, uint32_t width, uint32_t height, const RenderSettings& s) {
  shader::PostPush push{};
  push.color_in = input.address;
  push.color_out = output.address;
  push.width = width;
  push.height = height;
  push.levels = s.flatten_levels >= 2 ? uint32_t(s.flatten_levels) : 0u;
  push.contrast = s.contrast;
  push.brightness = s.brightness;
  push.saturation = s.saturation;
  push.sharpen = s.sharpen;
  gpu::recordDispatch(cmd, pass.pipelines[s.sharpen != 0.0f ? 1 : 0], push, shader::pixelGroups(width), shader::pixelGroups(height));
}

std::unique_ptr<FrameStage> makePostStage(const gpu::VulkanContext& context) {
  return std::make_unique<PostStage>(context);
}

}  // namespace fibscope
