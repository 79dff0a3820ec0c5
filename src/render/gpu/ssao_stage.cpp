// Shading: screen-space ambient occlusion (ssao.comp, Vogel spiral with
// interleaved sampling, multi-scale) and its depth-aware blur
// (ssao_blur.comp, x then y), in the covered tiles. Formulas:
// shared/shade_push.h.
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/shading_stages.h"
#include "shared/render_config.h"
#include "shared/shade_push.h"

namespace fibscope {
namespace {

class SsaoStage final : public FrameStage {
 public:
  explicit SsaoStage(const gpu::VulkanContext& context) {
    const gpu::WorkgroupSize tile{shader::kPixelGroupSize, shader::kPixelGroupSize};
    try {
      ssao_ = gpu::createComputePipeline(context, "ssao.comp", sizeof(shader::SsaoPush), tile);
      blur_ = gpu::createComputePipeline(context, "ssao_blur.comp", sizeof(shader::SsaoBlurPush), tile);
    } catch (...) {
      destroy(context);
      throw;
    }
  }
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyComputePipeline(context, blur_);
    gpu::destroyComputePipeline(context, ssao_);
  }
  uint32_t maxPasses() const override { return 2; }
  bool runs(const FrameContext& frame) const override { return ssaoRuns(frame.settings); }

  void record(FrameContext& frame) override {
    const GpuFrameTargets& t = frame.targets;
    const RenderSettings& s = frame.settings;
    {
      gpu::PassScope pass(frame.cmd, frame.timer, "ssao", gpu::kComputeToCompute);
      shader::SsaoPush push{};
      push.camera = t.camera.address;
      push.gbuffer = t.gbuffer.address;
      push.ao = t.ao.address;
      push.tiles = t.tile_list.address;
      push.width = t.width;
      push.height = t.height;
      push.radius_px = s.ssao_radius_px;
      push.epsilon_mm = shader::kSsaoEpsilonMm;
      push.range_mm = s.ssao_range_mm;
      push.strength = s.ssao_strength;
      push.scales = uint32_t(s.ao_scales);
      push.samples = uint32_t(s.ao_samples);
      gpu::recordDispatchIndirect(frame.cmd, ssao_, push, t.tile_list.buffer);
    }
    gpu::PassScope pass(frame.cmd, frame.timer, "ssao blur", gpu::kComputeToCompute);
    shader::SsaoBlurPush blur{};
    blur.camera = t.camera.address;
    blur.gbuffer = t.gbuffer.address;
    blur.tiles = t.tile_list.address;
    blur.width = t.width;
    blur.height = t.height;
    blur.depth_tolerance_mm = shader::kSsaoBlurDepthToleranceMm;
    blur.ao_in = t.ao.address;
    blur.ao_out = t.ao_blur.address;
    blur.step_x = 1;
    blur.step_y = 0;
    gpu::recordDispatchIndirect(frame.cmd, blur_, blur, t.tile_list.buffer);
    gpu::computeToComputeBarrier(frame.cmd);
    blur.ao_in = t.ao_blur.address;
    blur.ao_out = t.ao.address;
    blur.step_x = 0;
    blur.step_y = 1;
    gpu::recordDispatchIndirect(frame.cmd, blur_, blur, t.tile_list.buffer);
  }

 private:
  gpu::ComputePipeline ssao_;  // ssao.comp
  gpu::ComputePipeline blur_;  // ssao_blur.comp
};

}  // namespace

std::unique_ptr<FrameStage> makeSsaoStage(const gpu::VulkanContext& context) {
  return std::make_unique<SsaoStage>(context);
}

}  // namespace fibscope
