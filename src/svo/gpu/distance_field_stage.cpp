// Shading: the distance-field passes over the covered tiles, after the
// SSAO stage and before shade (gpu_distance_field.h):
//   df ao      shaders/df_ao.comp      Evans' AO factor -> targets.ao
//   df shadow  shaders/df_shadow.comp  soft-shadow factor -> targets.ao_blur
// Formulas: shaders/shared/distance_field.h.
#include <algorithm>

#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/shading_stages.h"
#include "shared/distance_field.h"
#include "shared/render_config.h"
#include "svo/gpu/gpu_distance_field.h"

namespace fibscope {
namespace {

void recordDfAo(FrameContext& frame, const gpu::ComputePipeline& pipeline, const GpuDistanceField& field) {
  const GpuFrameTargets& t = frame.targets;
  const RenderSettings& s = frame.settings;
  gpu::PassScope pass(frame.cmd, frame.timer, "df ao", gpu::kComputeToCompute);
  shader::DfAoPush push{};
  push.camera = t.camera.address;
  push.gbuffer = t.gbuffer.address;
  push.surface = frame.surfaces ? t.surface.address : 0;
  push.field = field.values.address;
  push.ao = t.ao.address;
  push.tiles = t.tile_list.address;
  push.grid = field.grid.shaderGrid();
  push.width = t.width;
  push.height = t.height;
  push.steps = uint32_t(std::clamp<int>(s.df_ao_steps, 1, int(shader::kDfMaxAoSteps)));
  push.delta = s.df_ao_delta_mm > 0.0f ? s.df_ao_delta_mm : field.grid.voxel;
  push.strength = s.df_ao_strength;
  gpu::recordDispatchIndirect(frame.cmd, pipeline, push, t.tile_list.buffer);
}

void recordDfShadow(FrameContext& frame, const gpu::ComputePipeline& pipeline, const GpuDistanceField& field) {
  const GpuFrameTargets& t = frame.targets;
  gpu::PassScope pass(frame.cmd, frame.timer, "df shadow", gpu::kComputeToCompute);
  shader::DfShadowPush push{};
  push.camera = t.camera.address;
  push.gbuffer = t.gbuffer.address;
  push.surface = frame.surfaces ? t.surface.address : 0;
  push.field = field.values.address;
  push.shadow = t.ao_blur.address;
  push.tiles = t.tile_list.address;
  push.grid = field.grid.shaderGrid();
  push.width = t.width;
  push.height = t.height;
  push.softness = frame.settings.df_shadow_softness;
  gpu::recordDispatchIndirect(frame.cmd, pipeline, push, t.tile_list.buffer);
}

class DistanceFieldStage final : public FrameStage {
 public:
  explicit DistanceFieldStage(const GpuDistanceField* field) : field_(field) {}
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyComputePipeline(context, shadow_);
    gpu::destroyComputePipeline(context, ao_);
  }
  uint32_t maxPasses() const override { return 2; }
  bool runs(const FrameContext& frame) const override {
    return field_ && field_->values.buffer != VK_NULL_HANDLE &&
           (distanceFieldAoRuns(frame.settings) || distanceFieldShadowsRun(frame.settings));
  }
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    if (distanceFieldAoRuns(settings)) pipelines(context, true, false);
    if (distanceFieldShadowsRun(settings)) pipelines(context, false, true);
  }

  void record(FrameContext& frame) override {
    const bool ao = distanceFieldAoRuns(frame.settings), shadow = distanceFieldShadowsRun(frame.settings);
    pipelines(frame.context, ao, shadow);
    if (ao) {
      recordDfAo(frame, ao_, *field_);
      frame.df_ao = true;
    }
    if (shadow) {
      recordDfShadow(frame, shadow_, *field_);
      frame.df_shadow = true;
    }
  }

 private:
  void pipelines(const gpu::VulkanContext& context, bool ao, bool shadow) {
    const gpu::WorkgroupSize tile{shader::kPixelGroupSize, shader::kPixelGroupSize};
    if (ao && ao_.pipeline == VK_NULL_HANDLE)
      ao_ = gpu::createComputePipeline(context, "df_ao.comp", sizeof(shader::DfAoPush), tile);
    if (shadow && shadow_.pipeline == VK_NULL_HANDLE)
      shadow_ = gpu::createComputePipeline(context, "df_shadow.comp", sizeof(shader::DfShadowPush), tile);
  }

  const GpuDistanceField* field_;
  gpu::ComputePipeline ao_, shadow_;  // made when first needed
};

}  // namespace

bool distanceFieldAoRuns(const RenderSettings& s) {
  return s.ssao && s.ao_method == AoMethod::Df && s.df_ao_strength > 0.0f;
}
bool distanceFieldShadowsRun(const RenderSettings& s) { return s.df_shadows && s.lighting != Lighting::None; }

FrameStageFactory distanceFieldStage(const GpuDistanceField* field) {
  return [field](const gpu::VulkanContext&) { return std::make_unique<DistanceFieldStage>(field); };
}

FrameStageList withDistanceFieldStage(FrameStageList stages, const GpuDistanceField* field) {
  using Factory = std::unique_ptr<FrameStage> (*)(const gpu::VulkanContext&);
  auto at = stages.begin();
  for (; at != stages.end(); ++at) {
    const Factory* f = at->target<Factory>();
    if (f && *f == &makeShadeStage) break;
  }
  stages.insert(at, distanceFieldStage(field));
  return stages;
}

}  // namespace fibscope
