// Surfaces: the anatomical slices of GpuScene::anatomy, ray-cast per pixel
// into the surface target by anatomy_slices.comp (shared/anatomy.h), as the
// sphere stage does its spheres. The slice parameters go in a block written
// with the frame's commands; the sampling picks one of two specialised
// pipelines.
#include <algorithm>
#include <array>
#include <cmath>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "render/gpu/anatomy.h"
#include "render/gpu/frame_stages.h"
#include "shared/anatomy.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

shader::vec4 column(const glm::dmat4& m, int c) {
  return {float(m[c][0]), float(m[c][1]), float(m[c][2]), float(m[c][3])};
}

class AnatomyStage final : public FrameStage {
 public:
  explicit AnatomyStage(const gpu::VulkanContext& context)
      : block_(gpu::createBuffer(context, sizeof(shader::AnatomySliceBlock), gpu::MemoryUse::DeviceLocal)) {}
  void destroy(const gpu::VulkanContext& context) override {
    for (gpu::ComputePipeline& p : variants_) gpu::destroyComputePipeline(context, p);
    gpu::destroyBuffer(context, block_);
  }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override {
    const RenderSettings& s = frame.settings;
    return frame.scene.anatomy && !frame.scene.anatomy->empty() && s.anatomy_opacity > 0.0f &&
           (s.show_slice_i || s.show_slice_j || s.show_slice_k);
  }
  bool drawsSurfaces() const override { return true; }

  void record(FrameContext& frame) override {
    const RenderSettings& s = frame.settings;
    const AnatomyGrid& grid = frame.scene.anatomy->grid();
    shader::AnatomySliceBlock block{};
    for (int c = 0; c < 4; ++c) block.world_to_voxel[c] = column(grid.world_to_voxel, c);
    const glm::dvec4 eye = grid.world_to_voxel * glm::dvec4(frame.camera.eye[0], frame.camera.eye[1],
                                                              frame.camera.eye[2], 1.0);
    block.eye_voxel = {float(eye.x), float(eye.y), float(eye.z), 0.0f};
    for (int a = 0; a < 3; ++a) {
      const PlaneEq plane = slicePlane(grid, a, slicePosition(s, a));
      block.normal[a] = {float(plane[0]), float(plane[1]), float(plane[2]), 0.0f};
    }
    block.position = {s.slice_i, s.slice_j, s.slice_k, 0.0f};
    block.dim_x = uint32_t(grid.dims.x);
    block.dim_y = uint32_t(grid.dims.y);
    block.dim_z = uint32_t(grid.dims.z);
    block.shown = (s.show_slice_i ? 1u : 0u) | (s.show_slice_j ? 2u : 0u) | (s.show_slice_k ? 4u : 0u);
    block.value_min = s.anatomy_min;
    block.value_max = s.anatomy_max;
    block.alpha = uint32_t(std::clamp(std::lround(s.anatomy_opacity * 255.0f), 1L, 255L));
    // The previous frame's reads of the block before the update, the
    // update before this frame's.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdUpdateBuffer(frame.cmd, block_.buffer, 0, sizeof(block), &block);
    gpu::recordBarrier(frame.cmd, gpu::kTransferToCompute);

    const gpu::ComputePipeline& pipeline = variant(frame.context, s.anatomy_sampling);
    gpu::PassScope pass(frame.cmd, frame.timer, "slices", gpu::kComputeToCompute);
    shader::AnatomySlicePush push{};
    push.camera = frame.targets.camera.address;
    push.block = block_.address;
    push.values = frame.scene.anatomy->values().address;
    push.surface = frame.targets.surface.address;
    push.width = frame.targets.width;
    push.height = frame.targets.height;
    gpu::recordDispatch(frame.cmd, pipeline, push, shader::pixelGroups(push.width), shader::pixelGroups(push.height));
  }

 private:
  const gpu::ComputePipeline& variant(const gpu::VulkanContext& context, SliceSampling sampling) {
    const uint32_t mode =
        sampling == SliceSampling::Nearest ? shader::kAnatomySamplingNearest : shader::kAnatomySamplingTrilinear;
    gpu::ComputePipeline& p = variants_[mode];
    if (p.pipeline == VK_NULL_HANDLE) {
      std::array<uint32_t, 1> spec{};
      spec[shader::kAnatomySpecSampling] = mode;
      p = gpu::createComputePipeline(context, "anatomy_slices.comp", sizeof(shader::AnatomySlicePush),
                                     gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize}, spec);
    }
    return p;
  }

  gpu::Buffer block_;                            // shader::AnatomySliceBlock
  std::array<gpu::ComputePipeline, 2> variants_{};  // by kAnatomySampling*, made at first use
};

}  // namespace

std::unique_ptr<FrameStage> makeAnatomyStage(const gpu::VulkanContext& context) {
  return std::make_unique<AnatomyStage>(context);
}

}  // namespace fibscope
