// Draws frames: runs the passes of the chosen pipeline into the shared
// frame targets (G-buffer, then the shaded RGBA8 image) with timestamps
// around every pass (DESIGN.md section 6). One renderer per frame size; it
// keeps the state that spans frames (pipelines, scratch buffers, the
// previous frame's visible fiblets for two-phase culling).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu_cull_passes.h"
#include "render/gpu_dataset.h"
#include "render/gpu_fiblet_passes.h"
#include "render/gpu_frame_targets.h"
#include "render/gpu_lines_pass.h"
#include "render/gpu_raw_passes.h"
#include "render/gpu_raw_tractogram.h"
#include "render/gpu_scene_table.h"
#include "render/gpu_shade_pass.h"
#include "render/render_settings.h"

namespace fibscope {

// What a frame draws: the fiblets of one or more datasets (compute
// pipeline), drawn together into one visibility buffer (the nearest fiber
// wins across datasets) with scene-global fiblet and fiber ids
// (render/gpu_scene_table.h: dataset i's fibers are fiber_base_i + its
// own), and, for the baselines, one tractogram as raw float vertices. A
// pipeline whose input is missing is an Error when the frame is recorded.
struct GpuScene {
  GpuScene() = default;
  // One dataset (or none), as most callers draw.
  GpuScene(const GpuDataset* fiblets, const GpuRawTractogram* raw_vertices = nullptr) : raw(raw_vertices) {
    if (fiblets) datasets.push_back(fiblets);
  }

  std::vector<const GpuDataset*> datasets;  // in drawing order (none null); the scene's fiber ids follow it
  const GpuRawTractogram* raw = nullptr;    // lines and raw-compute (one tractogram)
  // Per-fiber attributes (src/render/gpu_fiber_attributes.h), indexed by
  // the G-buffer's fiber id (scene-global: for one dataset its own ids); 0
  // means none. Each must hold an entry for every fiber of the drawn
  // datasets (the raw tractogram's, for the baselines), e.g.
  // GpuSceneFiberLengths for the scalars.
  VkDeviceAddress fiber_scalars = 0;   // float per fiber (ColorMode::Scalar)
  VkDeviceAddress selection_bits = 0;  // uint words: fiber f selected when bit f % 32 of word f / 32 is set;
                                       // 0 also means an empty selection (nothing dimmed)
};

class FrameRenderer {
 public:
  // Throws Error when a pipeline cannot be created or memory runs out.
  FrameRenderer(const gpu::VulkanContext& context, uint32_t width, uint32_t height);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  // New frame size (waits for the device to be idle).
  void resize(uint32_t width, uint32_t height);

  // Records one whole frame into `cmd` (the camera's size must be the
  // renderer's). Throws Error for a missing scene input or settings out of
  // range (line width outside [1, 4]).
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

 private:
  void release();

  const gpu::VulkanContext& context_;
  GpuFrameTargets targets_;
  FibletPasses fiblet_passes_;
  CullPasses cull_passes_;
  CullBuffers cull_buffers_;  // lists, pyramid and the two-phase visible bits (kept across frames)
  bool cull_stats_pending_ = false;  // the last frame was culled: collect() reads its counts
  gpu::Buffer scene_table_;  // shared/scene_table.h, written each compute frame
  SceneLayout layout_;
  // The scene fiblet total targets_.tangents was prepared for (UINT64_MAX:
  // none yet).
  uint64_t tangent_cache_for_ = UINT64_MAX;
  FibletBoundsPass bounds_pass_;  // fills a dataset's spheres before its first occlusion cull
  RawPasses raw_passes_;
  LinesPass lines_pass_;  // created at the first lines frame
  ShadePass shade_pass_;
  gpu::GpuTimer timer_;
  FrameStats pending_;
};

}  // namespace fibscope
