// Surfaces: the spline tubes ray-cast in the fragment shader over instanced
// tight boxes, then resolved into the surface target (tube_raster_stage.h).
#include "tubes/gpu/tube_raster_stage.h"

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/graphics_pipeline.h"
#include "gpu/pass_scope.h"
#include "shared/tube_raster.h"
#include "shared/tubes.h"

namespace fibscope {
namespace {

class TubeRasterStage final : public FrameStage {
 public:
  explicit TubeRasterStage(const GpuTubes* tubes) : tubes_(tubes) {}
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyBuffer(context, keys_);
    gpu::destroyComputePipeline(context, resolve_);
    gpu::destroyGraphicsPipeline(context, boxes_);
  }
  uint32_t maxPasses() const override { return 2; }
  bool runs(const FrameContext&) const override { return tubes_ && tubes_->segment_count > 0; }
  bool drawsSurfaces() const override { return true; }
  void check(const FrameContext& frame) const override {
    if (!frame.context.enabledFeatures().fragmentStoresAndAtomics)
      throw Error("tubes: the fragment-shader ray caster needs fragmentStoresAndAtomics, which the device lacks");
  }
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override { gpu::destroyBuffer(context, keys_); }

  void record(FrameContext& frame) override {
    if (boxes_.pipeline == VK_NULL_HANDLE) {
      gpu::GraphicsPipelineDesc desc;
      desc.vertex_shader = "tube_box.vert";
      desc.fragment_shader = "tube_box.frag";
      desc.color_format = VK_FORMAT_UNDEFINED;
      desc.push_constant_bytes = sizeof(shader::TubeBoxPush);
      boxes_ = gpu::createGraphicsPipeline(frame.context, desc);
      resolve_ =
          gpu::createComputePipeline(frame.context, "tube_raster_resolve.comp", sizeof(shader::TubeRasterResolvePush),
                                     gpu::WorkgroupSize{shader::kTubeResolveGroupSize, shader::kTubeResolveGroupSize});
    }
    const uint32_t width = frame.targets.width, height = frame.targets.height;
    if (!keys_.buffer)
      keys_ = gpu::createBuffer(frame.context, frame.targets.pixels() * sizeof(uint64_t), gpu::MemoryUse::DeviceLocal);
    // The previous frame's resolve read the keys before they are cleared.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdFillBuffer(frame.cmd, keys_.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
    // The clear, and the camera block the setup stage wrote (by transfer or
    // compute), before the box pass's shaders.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                   VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                   VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                   gpu::kStorageReadWrite});
    const uint32_t items = tubes_->subSegmentCount();
    {
      const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, gpu::kStorageReadWrite,
                                   VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite};
      gpu::PassScope pass(frame.cmd, frame.timer, "tube boxes", after);
      shader::TubeBoxPush push{};
      push.camera = frame.targets.camera.address;
      push.nodes = tubes_->nodes.address;
      push.segments = tubes_->segments.address;
      push.visibility = keys_.address;
      push.width = width;
      gpu::beginRenderingWithoutAttachments(frame.cmd, width, height);
      gpu::recordDraw(frame.cmd, boxes_, push, shader::kTubeBoxVertices, items);
      gpu::endRendering(frame.cmd);
    }
    {
      gpu::PassScope pass(frame.cmd, frame.timer, "tube resolve", gpu::kComputeToCompute);
      shader::TubeRasterResolvePush push{};
      push.camera = frame.targets.camera.address;
      push.nodes = tubes_->nodes.address;
      push.segments = tubes_->segments.address;
      push.visibility = keys_.address;
      push.surface = frame.targets.surface.address;
      push.width = width;
      push.height = height;
      const uint32_t g = shader::kTubeResolveGroupSize;
      gpu::recordDispatch(frame.cmd, resolve_, push, (width + g - 1) / g, (height + g - 1) / g);
    }
  }
  void collect(const gpu::VulkanContext&, FrameStats& stats) override { stats.tube_method_bytes = keys_.size; }

 private:
  const GpuTubes* tubes_;
  gpu::GraphicsPipeline boxes_;  // made at the first frame with tubes
  gpu::ComputePipeline resolve_;
  gpu::Buffer keys_;  // uint64_t visibility key per pixel, row-major
};

}  // namespace

FrameStageFactory tubeRasterRaycastStage(const GpuTubes* tubes) {
  return [tubes](const gpu::VulkanContext&) { return std::make_unique<TubeRasterStage>(tubes); };
}

}  // namespace fibscope
