// Draws frames: runs a list of frame stages (frame_stage.h; the
// standard list in frame_stages.h) into the shared frame targets
// (G-buffer and surface target, then the shaded RGBA8 image) with
// timestamps around every pass (DESIGN.md section 6). One renderer per
// frame size; its stages keep the state that spans frames (pipelines,
// scratch buffers, the previous frame's visible fiblets for two-phase
// culling).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu/frame_stage.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/scene.h"
#include "render/gpu/scene_table.h"
#include "render/render_settings.h"

namespace fibscope {

class FrameRenderer {
 public:
  // Makes every stage of `stages` (in order) and a timer for the sum of
  // their passes. Throws Error when a pipeline cannot be created or memory
  // runs out.
  FrameRenderer(const gpu::VulkanContext& context, uint32_t width, uint32_t height,
                const FrameStageList& stages = standardFrameStages());
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  // New frame size (waits for the device to be idle).
  void resize(uint32_t width, uint32_t height);
  // Makes now what frames with these settings will need (shader variants,
  // the lines pipeline), so that the first of them does not wait for it.
  void prepare(const RenderSettings& settings);

  // Records one whole frame into `cmd` (the camera's size must be the
  // renderer's). With slab_follows_slice and a scene anatomy, the slab lies
  // around the active slice (withSlabFollowingSlice). Throws Error for a
  // missing scene input or settings out of their range
  // (render/settings_table.h), before anything is recorded.
  void record(VkCommandBuffer cmd, const Camera& camera, const RenderSettings& settings, const GpuScene& scene);
  // The statistics of the frame last recorded, once its submission has
  // completed.
  FrameStats collect();
  // record + submit + wait + collect.
  FrameStats render(const Camera& camera, const RenderSettings& settings, const GpuScene& scene);

  const GpuFrameTargets& targets() const { return targets_; }
  // The numbering of the last compute frame recorded (its G-buffer's fiber
  // ids: locateSceneFiber maps them to a dataset and its fiber).
  const SceneLayout& sceneLayout() const { return layout_; }
  // Timed passes a frame may hold: the sum of the stages' maxPasses.
  uint32_t passCapacity() const { return timer_.capacity; }

 private:
  void release();

  const gpu::VulkanContext& context_;
  GpuFrameTargets targets_;
  std::vector<std::unique_ptr<FrameStage>> stages_;  // in frame order
  std::vector<FrameStage*> ran_;                     // those the last recorded frame ran
  SceneLayout layout_;
  gpu::GpuTimer timer_;
  FrameStats pending_;
};

}  // namespace fibscope
