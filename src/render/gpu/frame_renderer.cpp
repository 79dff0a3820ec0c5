#include "render/gpu/frame_renderer.h"

#include <string>

#include "core/error.h"
#include "gpu/submit.h"
#include "render/gpu/anatomy.h"
#include "render/settings_table.h"

namespace fibscope {

FrameRenderer::FrameRenderer(const gpu::VulkanContext& context, uint32_t width, uint32_t height,
                             const FrameStageList& stages)
    : context_(context) {
  try {
    targets_ = createFrameTargets(context, width, height);
    uint32_t passes = 0;
    for (const FrameStageFactory& make : stages) {
      stages_.push_back(make(context));
      passes += stages_.back()->maxPasses();
    }
    timer_ = gpu::createGpuTimer(context, passes);
  } catch (...) {
    release();
    throw;
  }
}

FrameRenderer::~FrameRenderer() { release(); }

void FrameRenderer::release() {
  gpu::destroyGpuTimer(context_, timer_);
  for (auto it = stages_.rbegin(); it != stages_.rend(); ++it) (*it)->destroy(context_);
  stages_.clear();
  destroyFrameTargets(context_, targets_);
}

void FrameRenderer::resize(uint32_t width, uint32_t height) {
  if (width == targets_.width && height == targets_.height) return;
  vkDeviceWaitIdle(context_.device());
  GpuFrameTargets fresh = createFrameTargets(context_, width, height);
  destroyFrameTargets(context_, targets_);
  targets_ = fresh;
  for (auto& stage : stages_) stage->resize(context_, width, height);
}

void FrameRenderer::prepare(const RenderSettings& settings) {
  for (auto& stage : stages_) stage->prepare(context_, settings);
}

void FrameRenderer::record(VkCommandBuffer cmd, const Camera& camera, const RenderSettings& given,
                           const GpuScene& scene) {
  // The slab around the active anatomical slice, when asked to follow it.
  const RenderSettings settings =
      scene.anatomy && !scene.anatomy->empty() ? withSlabFollowingSlice(given, scene.anatomy->grid()) : given;
  if (camera.width != targets_.width || camera.height != targets_.height)
    throw Error("render: camera is " + std::to_string(camera.width) + " x " + std::to_string(camera.height) +
                " px, the frame " + std::to_string(targets_.width) + " x " + std::to_string(targets_.height));
  validateRenderSettings(settings);
  for (const GpuDataset* dataset : scene.datasets)
    if (!dataset) throw Error("render: a null dataset in the scene");
  const bool compute = drawsFiblets(settings.pipeline);
  if (!compute && !scene.raw)  // the per-fiber attributes are the raw tractogram's fibers'
    throw Error("render: the " + std::string(renderPipelineName(settings.pipeline)) +
                " pipeline needs the raw tractogram");
  // Scene-global numbering (scene_table.h): Error above 2^28 fiblets.
  if (compute) layout_ = fibscope::sceneLayout(scene.datasets);

  pending_ = {};
  FrameContext frame{cmd, context_, camera, settings, scene, targets_, &timer_, pending_, layout_};
  // Per-fiber attributes cover the fibers of the tractogram drawn.
  frame.fiber_count = compute ? layout_.fibers : scene.raw->streamlineCount();
  // Surfaces first (whether a surface stage runs does not depend on it),
  // then the stages this frame runs, each told whether there are surfaces.
  for (auto& stage : stages_) frame.surfaces |= stage->drawsSurfaces() && stage->runs(frame);
  ran_.clear();
  for (auto& stage : stages_)
    if (stage->runs(frame)) ran_.push_back(stage.get());
  for (FrameStage* stage : ran_) stage->check(frame);
  if (frame.surfaces) ensureSurfaceTarget(context_, targets_);

  gpu::resetGpuTimer(cmd, timer_);
  for (FrameStage* stage : ran_) stage->record(frame);
}

FrameStats FrameRenderer::collect() {
  FrameStats stats = pending_;
  for (FrameStage* stage : ran_) stage->collect(context_, stats);
  for (const gpu::PassTime& t : gpu::readGpuTimer(context_, timer_)) {
    stats.passes.push_back({t.name, t.ms});
    stats.gpu_ms += t.ms;
  }
  return stats;
}

FrameStats FrameRenderer::render(const Camera& camera, const RenderSettings& settings, const GpuScene& scene) {
  gpu::submitOnce(context_, [&](VkCommandBuffer cmd) { record(cmd, camera, settings, scene); });
  return collect();
}

}  // namespace fibscope
