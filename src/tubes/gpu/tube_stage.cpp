// Surfaces: the spline tubes, drawn by the method RenderSettings::tube_method
// names at each frame (compute ray casting, fragment-shader ray casting or
// tessellation), so the command line, bench and the viewer's panel switch
// methods without rebuilding the frame's stage list. Each method is a stage
// of its own (tube_raycast_stage.cpp, ...), made at the first frame that
// uses it and kept, so switching back and forth makes no pipelines twice.
#include <array>
#include <memory>

#include "core/error.h"
#include "render/gpu/frame_stages.h"
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/gpu/tube_raster_stage.h"
#include "tubes/gpu/tube_tess_stage.h"

namespace fibscope {
namespace {

constexpr size_t kMethods = 3;
constexpr uint32_t kMaxMethodPasses = 4;

class TubeStage final : public FrameStage {
 public:
  explicit TubeStage(const GpuTubes* tubes) : tubes_(tubes) {}
  void destroy(const gpu::VulkanContext& context) override {
    for (auto& m : methods_)
      if (m) m->destroy(context);
  }
  // The frame's timer is sized once, before any method is made: room for
  // the method with the most passes (a larger timer costs nothing).
  uint32_t maxPasses() const override { return kMaxMethodPasses; }
  bool runs(const FrameContext&) const override { return tubes_ && tubes_->segment_count > 0; }
  bool drawsSurfaces() const override { return true; }
  // The method's own checks (settings it refuses, features the device
  // lacks): the method is made here if it was not yet, as record would.
  void check(const FrameContext& frame) const override {
    method(frame.context, frame.settings.tube_method).check(frame);
  }
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    method(context, settings.tube_method).prepare(context, settings);
  }
  void resize(const gpu::VulkanContext& context, uint32_t width, uint32_t height) override {
    for (auto& m : methods_)
      if (m) m->resize(context, width, height);
  }
  void record(FrameContext& frame) override {
    FrameStage& m = method(frame.context, frame.settings.tube_method);
    m.record(frame);
    recorded_ = &m;
  }
  void collect(const gpu::VulkanContext& context, FrameStats& stats) override {
    if (recorded_) recorded_->collect(context, stats);
    recorded_ = nullptr;
  }

 private:
  // The method's factory; throws Error for one this build does not have.
  FrameStageFactory factory(TubeMethod m) const {
    switch (m) {
      case TubeMethod::Compute:
        return tubeRaycastStage(tubes_);
      case TubeMethod::Raycast:
        return tubeRasterRaycastStage(tubes_);
      case TubeMethod::Tessellation:
        return tubeTessellationStage(tubes_);
    }
    throw Error("tube-method " + std::string(tubeMethodName(m)) + ": not available in this build");
  }
  FrameStage& method(const gpu::VulkanContext& context, TubeMethod m) const {
    std::unique_ptr<FrameStage>& slot = methods_.at(size_t(m));
    if (!slot) slot = factory(m)(context);
    return *slot;
  }

  const GpuTubes* tubes_;
  mutable std::array<std::unique_ptr<FrameStage>, kMethods> methods_;  // made by the first frame (or check) using each
  FrameStage* recorded_ = nullptr;  // the method recorded since the last collect
};

}  // namespace

FrameStageFactory tubeStage(const GpuTubes* tubes) {
  return [tubes](const gpu::VulkanContext&) { return std::make_unique<TubeStage>(tubes); };
}

}  // namespace fibscope
