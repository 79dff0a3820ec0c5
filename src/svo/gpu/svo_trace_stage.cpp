// Surfaces: the SVO's straight streamtubes ray-traced (or its curved ones
// sphere-traced) by compute
// (svo_trace.comp), into the surface target like every surface pass.
#include <algorithm>
#include <cmath>

#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "shared/svo.h"
#include "svo/gpu/gpu_svo.h"

namespace fibscope {
namespace {

class SvoTraceStage final : public FrameStage {
 public:
  SvoTraceStage(const GpuSvo* svo, const GpuTubes* tubes, SvoTraceOptions options)
      : svo_(svo), tubes_(tubes), options_(options) {}
  void destroy(const gpu::VulkanContext& context) override { gpu::destroyComputePipeline(context, trace_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext&) const override {
    return svo_ && tubes_ && svo_->nodes.buffer && tubes_->segment_count > 0;
  }
  bool drawsSurfaces() const override { return true; }

  void record(FrameContext& frame) override {
    if (trace_.pipeline == VK_NULL_HANDLE)
      trace_ = gpu::createComputePipeline(frame.context, "svo_trace.comp", sizeof(shader::SvoTracePush),
                                          gpu::WorkgroupSize{shader::kSvoTraceTile, shader::kSvoTraceTile});
    const uint32_t width = frame.targets.width, height = frame.targets.height;
    gpu::PassScope pass(frame.cmd, frame.timer, "svo trace", gpu::kComputeToCompute);
    shader::SvoTracePush push{};
    push.camera = frame.targets.camera.address;
    push.svo_nodes = svo_->nodes.address;
    push.decoration = svo_->decoration.address;
    push.nodes = tubes_->nodes.address;
    push.segments = tubes_->segments.address;
    push.surface = frame.targets.surface.address;
    push.origin_x = svo_->grid.origin.x;
    push.origin_y = svo_->grid.origin.y;
    push.origin_z = svo_->grid.origin.z;
    push.voxel = svo_->grid.voxel;
    push.levels = svo_->grid.levels;
    push.width = width;
    push.height = height;
    push.curved = svo_->grid.curved ? 1u : 0u;
    push.lod_px = options_.live_lod_px ? std::clamp(*options_.live_lod_px, 0.0f, 1e6f) : options_.lod_px;
    // The footprint of a pixel at unit distance on the view axis (slightly
    // smaller than off axis: a node there is stopped a little later, never
    // earlier).
    push.pixel_angle = float(2.0 * std::tan(0.5 * frame.camera.fov_y_deg * M_PI / 180.0) / double(height));
    push.svo_lod = svo_->lod.address;
    push.stats = options_.stats;
    gpu::recordDispatch(frame.cmd, trace_, push, (width + shader::kSvoTraceTile - 1) / shader::kSvoTraceTile,
                        (height + shader::kSvoTraceTile - 1) / shader::kSvoTraceTile);
  }

 private:
  const GpuSvo* svo_;
  const GpuTubes* tubes_;
  SvoTraceOptions options_;
  gpu::ComputePipeline trace_;  // made at the first frame
};

}  // namespace

FrameStageFactory svoTraceStage(const GpuSvo* svo, const GpuTubes* tubes, SvoTraceOptions options) {
  return [svo, tubes, options](const gpu::VulkanContext&) {
    return std::make_unique<SvoTraceStage>(svo, tubes, options);
  };
}

}  // namespace fibscope
