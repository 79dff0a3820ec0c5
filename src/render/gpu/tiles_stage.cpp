// Shading, first stage: the image filled with the background and the 8 x 8
// tiles with a covered pixel listed (tile_classify.comp), the list
// finalised into the indirect dispatch of the tile passes (ssao, blur,
// shade: one workgroup per covered tile). On a CPU device, whose SIMD lanes
// run every branch, the empty tiles are most of a frame's cost otherwise.
#include <algorithm>

#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/shading_stages.h"
#include "shared/cull_push.h"
#include "shared/fiblet_list.h"
#include "shared/render_config.h"
#include "shared/shade_push.h"

namespace fibscope {
namespace {

class TilesStage final : public FrameStage {
 public:
  explicit TilesStage(const gpu::VulkanContext& context) {
    try {
      classify_ = gpu::createComputePipeline(context, "tile_classify.comp", sizeof(shader::TileClassifyPush),
                                             gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
      finalize_ = createListFinalizePipeline(context);
    } catch (...) {
      destroy(context);
      throw;
    }
  }
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyComputePipeline(context, finalize_);
    gpu::destroyComputePipeline(context, classify_);
  }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext&) const override { return true; }

  void record(FrameContext& frame) override {
    const GpuFrameTargets& t = frame.targets;
    const gpu::Buffer& output = shadeTarget(frame.settings) == ShadeTarget::Shaded ? t.shaded : t.color;
    // The list and the filled image before the tile passes and their
    // indirect reads of the list's header.
    gpu::PassScope pass(frame.cmd, frame.timer, "tiles", gpu::kComputeToIndirect);
    // Earlier reads of the list (the previous frame's dispatches) and of
    // the image (its copy out) before the fills.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT |
                                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                                   0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdFillBuffer(frame.cmd, t.tile_flags.buffer, 0, t.tiles() * sizeof(uint32_t), 0);
    vkCmdFillBuffer(frame.cmd, t.tile_list.buffer, 0, sizeof(shader::FibletListHeader), 0);
    vkCmdFillBuffer(frame.cmd, output.buffer, 0, t.pixels() * sizeof(uint32_t), packRgba8(frame.settings.background));
    gpu::recordBarrier(frame.cmd, gpu::kTransferToCompute);
    shader::TileClassifyPush classify{};
    classify.gbuffer = t.gbuffer.address;
    classify.flags = t.tile_flags.address;
    classify.tiles = t.tile_list.address;
    classify.width = t.width;
    classify.height = t.height;
    gpu::recordDispatch(frame.cmd, classify_, classify, shader::pixelGroups(t.width), shader::pixelGroups(t.height));
    gpu::computeToComputeBarrier(frame.cmd);
    shader::FibletListFinalizePush finalize{};
    finalize.list = t.tile_list.address;
    finalize.items_per_group = 1;
    finalize.max_groups_x = frame.context.limits().maxComputeWorkGroupCount[0];
    gpu::recordDispatch(frame.cmd, finalize_, finalize, 1);
  }

 private:
  gpu::ComputePipeline classify_;  // tile_classify.comp
  gpu::ComputePipeline finalize_;  // fiblet_list_finalize.comp, on the tile list
};

}  // namespace

uint32_t packRgba8(const std::array<float, 3>& c) {
  uint32_t packed = 0xFF000000u;
  for (int k = 0; k < 3; ++k) packed |= uint32_t(std::clamp(c[k], 0.0f, 1.0f) * 255.0f + 0.5f) << (8 * k);
  return packed;
}

bool ssaoRuns(const RenderSettings& s) {
  return s.ssao && s.ao_method == AoMethod::Ssao && s.ssao_radius_px > 0.0f && s.ssao_strength > 0.0f;
}

std::unique_ptr<FrameStage> makeTilesStage(const gpu::VulkanContext& context) {
  return std::make_unique<TilesStage>(context);
}

}  // namespace fibscope
