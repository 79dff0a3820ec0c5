// A frame is a list of stages (STYLE.md: "a pass is a stage"). Each stage
// owns its pipelines and scratch, says whether the frame needs it, and
// records its passes into the frame's command buffer, each pass inside a
// gpu::PassScope (timestamps and the barrier after it). The frame renderer
// (frame_renderer.h) runs the list in order and sizes its GPU timer
// from the stages' maxPasses, so a new pass is one shader file, one stage
// file and one line in the list (frame_stages.cpp).
//
// Order of the standard list and what each stage leaves for the next:
//   setup         camera block written, visibility (and surface target) cleared
//   geometry      one of compute / raw-compute / lines / geometry /
//                 tessellation: the lines' G-buffer
//   surfaces      any number: nearer-wins writes into the surface target
//   merge         surface pixels nearer than the lines into the G-buffer
//   shading       tiles, SSAO, shade, post effects, FXAA: the G-buffer -> RGBA8
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/scene.h"
#include "render/gpu/scene_table.h"
#include "render/render_settings.h"

namespace fibscope {

// What the stages of one frame share. The renderer fills it before the
// first stage records; stages add to `stats` (and the setup stage sets
// scene_table).
struct FrameContext {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  const gpu::VulkanContext& context;
  const Camera& camera;
  const RenderSettings& settings;
  const GpuScene& scene;
  GpuFrameTargets& targets;
  gpu::GpuTimer* timer = nullptr;  // every pass of the frame is timed on it
  FrameStats& stats;
  // The compute pipeline's scene numbering (scene_table.h), and its
  // table on the device (the setup stage writes it and sets the address);
  // empty for the baselines.
  const SceneLayout& layout;
  VkDeviceAddress scene_table = 0;
  // Fibers the per-fiber attributes (scene.fiber_scalars, selection bits)
  // cover: the scene's for compute, the raw tractogram's for the baselines.
  uint32_t fiber_count = 0;
  // A surface stage runs this frame: the surface target exists, is cleared
  // by the setup stage and merged into the G-buffer by the merge stage.
  bool surfaces = false;
  // Set by the distance-field stage (src/svo/gpu/gpu_distance_field.h)
  // when it wrote this frame's AO factor into targets.ao (in place of
  // SSAO) and its shadow factor into targets.ao_blur (SSAO's scratch,
  // unused then): the shade pass reads them.
  bool df_ao = false;
  bool df_shadow = false;
};

class FrameStage {
 public:
  virtual ~FrameStage() = default;
  // Releases the stage's Vulkan objects (the device is idle); the stage is
  // not used again.
  virtual void destroy(const gpu::VulkanContext& context) = 0;
  // The most timed passes the stage records in one frame: the frame's
  // timer holds the sum over the list.
  virtual uint32_t maxPasses() const = 0;
  // Whether the frame needs the stage (pipeline, settings, scene).
  virtual bool runs(const FrameContext& frame) const = 0;
  // True for stages that draw into the surface target (when they run).
  virtual bool drawsSurfaces() const { return false; }
  // Throws Error for a scene input the stage needs and does not find; the
  // renderer asks every stage that runs before any records.
  virtual void check(const FrameContext& /*frame*/) const {}
  // Records the stage's passes.
  virtual void record(FrameContext& frame) = 0;
  // After the frame's submission completed: counts the stage read back.
  virtual void collect(const gpu::VulkanContext& /*context*/, FrameStats& /*stats*/) {}
  // Pipelines and variants the settings will need, made now rather than in
  // the first frame (render makes them while the file is read).
  virtual void prepare(const gpu::VulkanContext& /*context*/, const RenderSettings& /*settings*/) {}
  // A new frame size (the device is idle): size-dependent state is stale.
  virtual void resize(const gpu::VulkanContext& /*context*/, uint32_t /*width*/, uint32_t /*height*/) {}
};

// Makes a stage's pipelines (throws Error when one cannot be made).
using FrameStageFactory = std::function<std::unique_ptr<FrameStage>(const gpu::VulkanContext&)>;
using FrameStageList = std::vector<FrameStageFactory>;

}  // namespace fibscope
