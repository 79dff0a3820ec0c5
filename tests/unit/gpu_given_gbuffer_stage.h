// A frame stage for tests of the stages after the geometry: it copies a
// G-buffer made on the host into the frame's (in place of the pipelines'
// geometry stages) and says how many fibers the per-fiber attributes cover.
// With it a test runs the real shading stages through FrameRenderer on
// hand-made texels:
//   FrameRenderer r(context, w, h, givenGBufferStages(texels, fibers));
#pragma once

#include <type_traits>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stage.h"
#include "render/gpu/frame_stages.h"
#include "shared/gbuffer.h"

namespace fibscope::test {

// Copies texels made on the host into one of the frame's targets: the
// G-buffer (in place of the geometry stages; it also says how many fibers
// the per-fiber attributes cover) or the surface target (as a surface
// stage, for the merge to take).
template <typename Texel>
class GivenTexelsStage final : public FrameStage {
 public:
  GivenTexelsStage(const gpu::VulkanContext& context, const std::vector<Texel>& texels, uint32_t fiber_count)
      : fiber_count_(fiber_count) {
    staging_ = gpu::createBuffer(context, texels.size() * sizeof(texels[0]), gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context, staging_, texels.data(), texels.size() * sizeof(texels[0]));
  }
  static constexpr bool kSurface = std::is_same_v<Texel, shader::SurfaceTexel>;
  void destroy(const gpu::VulkanContext& context) override { gpu::destroyBuffer(context, staging_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext&) const override { return true; }
  bool drawsSurfaces() const override { return kSurface; }
  void record(FrameContext& frame) override {
    if constexpr (kSurface) {
      // After the setup stage's clear of the same buffer.
      gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT});
    } else {
      frame.fiber_count = fiber_count_;
    }
    gpu::PassScope pass(frame.cmd, frame.timer, kSurface ? "given surfaces" : "given g-buffer",
                        {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite});
    const VkBufferCopy region{0, 0, staging_.size};
    const gpu::Buffer& target = kSurface ? frame.targets.surface : frame.targets.gbuffer;
    vkCmdCopyBuffer(frame.cmd, staging_.buffer, target.buffer, 1, &region);
  }

 private:
  gpu::Buffer staging_;
  uint32_t fiber_count_;
};

using GivenGBufferStage = GivenTexelsStage<shader::GBufferTexel>;
using GivenSurfaceStage = GivenTexelsStage<shader::SurfaceTexel>;

// setup, the given G-buffer (and, when given, surface target and the
// merge), then the standard shading stages.
inline FrameStageList givenGBufferStages(const std::vector<shader::GBufferTexel>& texels, uint32_t fiber_count,
                                         const std::vector<shader::SurfaceTexel>& surfaces = {}) {
  FrameStageList list = {makeSetupStage, [texels, fiber_count](const gpu::VulkanContext& context) {
                           return std::make_unique<GivenGBufferStage>(context, texels, fiber_count);
                         }};
  if (!surfaces.empty()) {
    list.push_back([surfaces](const gpu::VulkanContext& context) {
      return std::make_unique<GivenSurfaceStage>(context, surfaces, 0);
    });
    list.push_back(makeSurfaceMergeStage);
  }
  for (FrameStageFactory& f : shadingStages()) list.push_back(std::move(f));
  return list;
}

}  // namespace fibscope::test
