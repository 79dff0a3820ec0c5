#include "render/gpu_frame_renderer.h"

#include <string>

#include "core/error.h"
#include "gpu/submit.h"
#include "render/reference_raster.h"

namespace fibscope {
namespace {

constexpr uint32_t kMaxPassesPerFrame = 16;

}  // namespace

FrameRenderer::FrameRenderer(const gpu::VulkanContext& context, uint32_t width, uint32_t height) : context_(context) {
  try {
    targets_ = createFrameTargets(context, width, height);
    fiblet_passes_ = createFibletPasses(context);
    cull_passes_ = createCullPasses(context);
    bounds_pass_ = createFibletBoundsPass(context);
    raw_passes_ = createRawPasses(context);
    shade_pass_ = createShadePass(context, width, height);
    scene_table_ = createSceneTableBuffer(context);
    timer_ = gpu::createGpuTimer(context, kMaxPassesPerFrame);
  } catch (...) {
    release();
    throw;
  }
}

FrameRenderer::~FrameRenderer() { release(); }

void FrameRenderer::release() {
  gpu::destroyGpuTimer(context_, timer_);
  gpu::destroyBuffer(context_, scene_table_);
  destroyShadePass(context_, shade_pass_);
  destroyLinesPass(context_, lines_pass_);
  destroyRawPasses(context_, raw_passes_);
  destroyCullBuffers(context_, cull_buffers_);
  destroyFibletBoundsPass(context_, bounds_pass_);
  destroyCullPasses(context_, cull_passes_);
  destroyFibletPasses(context_, fiblet_passes_);
  destroyFrameTargets(context_, targets_);
}

void FrameRenderer::resize(uint32_t width, uint32_t height) {
  if (width == targets_.width && height == targets_.height) return;
  vkDeviceWaitIdle(context_.device());
  releaseLinesAttachments(context_, lines_pass_);  // made again at the next lines frame
  GpuFrameTargets fresh = createFrameTargets(context_, width, height);
  try {
    resizeShadePass(context_, shade_pass_, width, height);
  } catch (...) {
    destroyFrameTargets(context_, fresh);
    throw;
  }
  destroyFrameTargets(context_, targets_);
  targets_ = fresh;
  tangent_cache_for_ = UINT64_MAX;  // the fresh targets have no tangent cache
}

void FrameRenderer::record(VkCommandBuffer cmd, const Camera& camera, const RenderSettings& settings,
                           const GpuScene& scene) {
  if (camera.width != targets_.width || camera.height != targets_.height)
    throw Error("render: camera is " + std::to_string(camera.width) + " x " + std::to_string(camera.height) +
                " px, the frame " + std::to_string(targets_.width) + " x " + std::to_string(targets_.height));
  if (!(settings.line_width_px >= kMinLineWidth && settings.line_width_px <= kMaxLineWidth))
    throw Error("render: line width must lie in [1, 4] px, got " + std::to_string(settings.line_width_px));
  validateShadeSettings(settings);
  if (settings.pipeline == RenderPipeline::Compute && scene.datasets.empty())
    throw Error("render: the compute pipeline needs fiblets");
  for (const GpuDataset* dataset : scene.datasets)
    if (!dataset) throw Error("render: a null dataset in the scene");
  if (settings.pipeline != RenderPipeline::Compute && !scene.raw)
    throw Error("render: the " + std::string(renderPipelineName(settings.pipeline)) +
                " pipeline needs the raw tractogram");
  // Created at the first lines frame: compute-only devices have no
  // graphics queue and never need it.
  if (settings.pipeline == RenderPipeline::Lines) {
    if (lines_pass_.pipeline.pipeline == VK_NULL_HANDLE) lines_pass_ = createLinesPass(context_);
    ensureLinesAttachments(context_, lines_pass_, targets_.width, targets_.height);
  }

  pending_ = {};
  gpu::resetGpuTimer(cmd, timer_);

  // Frame setup: the camera block and an empty visibility buffer (the
  // lines pipeline has its own depth attachment instead).
  const bool lines = settings.pipeline == RenderPipeline::Lines;
  gpu::beginPass(cmd, timer_, "clear");
  const shader::CameraBlock block = makeCameraBlock(camera, settings.line_width_px);
  vkCmdUpdateBuffer(cmd, targets_.camera.buffer, 0, sizeof(block), &block);
  if (!lines) vkCmdFillBuffer(cmd, targets_.visibility.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
  gpu::endPass(cmd, timer_);
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     lines ? VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);

  if (settings.pipeline == RenderPipeline::Lines) {
    // Baseline: every streamline as a line strip, no culling.
    pending_.segments_total = scene.raw->segmentCount();
    gpu::beginPass(cmd, timer_, "lines");
    recordLines(cmd, context_, lines_pass_, *scene.raw, targets_, settings.line_width_px);
    gpu::endPass(cmd, timer_);
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  } else if (settings.pipeline == RenderPipeline::RawCompute) {
    // Baseline: every raw segment through the compute raster, no culling.
    pending_.segments_total = scene.raw->segmentCount();
    gpu::beginPass(cmd, timer_, "raster");
    recordRawRaster(cmd, context_, raw_passes_, *scene.raw, targets_);
    gpu::endPass(cmd, timer_);
    gpu::computeToComputeBarrier(cmd);

    gpu::beginPass(cmd, timer_, "resolve");
    recordRawResolve(cmd, raw_passes_, *scene.raw, targets_);
    gpu::endPass(cmd, timer_);
    gpu::computeToComputeBarrier(cmd);
  } else {
    // Scene-global numbering (gpu_scene_table.h): Error above 2^28 fiblets.
    layout_ = fibscope::sceneLayout(scene.datasets);
    pending_.fiblets_total = layout_.fiblets;
    recordSceneTableUpdate(cmd, scene_table_, layout_);
    // The rasters keep each drawn segment's tangent (at the global fiblet)
    // so the resolve need not decode again (when the scene's cache fits the
    // budget): sized when the scene's fiblet total changes, not per frame.
    // (The cache's contents never outlive a frame: every frame's rasters
    // write what its resolve reads.)
    if (tangent_cache_for_ != layout_.fiblets) {
      prepareTangentCache(context_, targets_, layout_.fiblets);
      tangent_cache_for_ = layout_.fiblets;
    }
    cull_stats_pending_ = settings.culling != CullingMode::None && pending_.fiblets_total > 0;
    if (settings.culling == CullingMode::TwoPhase) {
      // The occlusion test wants each dataset's exact spheres: computed in
      // this frame for a dataset that has none yet (frustum culling keeps
      // the record's looser bound; see gpu_dataset.h for why not at upload).
      bool missing = false;
      for (const SceneEntry& e : layout_.entries) missing |= !e.dataset->fibletBoundsReady();
      if (missing) {
        gpu::beginPass(cmd, timer_, "fiblet bounds");
        for (const SceneEntry& e : layout_.entries) e.dataset->recordFibletBoundsOnce(cmd, bounds_pass_);
        gpu::endPass(cmd, timer_);
      }
    }
    if (cull_stats_pending_) {
      // Cull passes, both rasters (and the pyramid and second phase for
      // TwoPhase) of every dataset; fiblets_drawn and fiblets_lod come from
      // collect().
      std::vector<uint32_t> fiblets;
      for (const SceneEntry& e : layout_.entries) fiblets.push_back(e.dataset->block().fiblet_count);
      prepareCullBuffers(context_, cull_buffers_, fiblets, targets_.width, targets_.height);
      recordCulledRaster(cmd, context_, cull_passes_, fiblet_passes_, layout_, targets_, cull_buffers_,
                         CullFrame{settings.culling, settings.lod_pixels, cullFocalPixels(camera)}, timer_);
    } else {
      gpu::beginPass(cmd, timer_, "raster");
      for (const SceneEntry& e : layout_.entries)
        recordFibletRasterAll(cmd, context_, fiblet_passes_, *e.dataset, targets_, e.fiblet_base);
      gpu::endPass(cmd, timer_);
      pending_.fiblets_drawn = pending_.fiblets_total;
      cull_buffers_.history_valid = false;  // two-phase history skips this frame
    }
    gpu::computeToComputeBarrier(cmd);

    gpu::beginPass(cmd, timer_, "resolve");
    recordFibletResolve(cmd, fiblet_passes_, scene_table_.address, targets_);
    gpu::endPass(cmd, timer_);
    gpu::computeToComputeBarrier(cmd);
  }

  // Per-fiber attributes cover the fibers of the tractogram drawn.
  ShadeFiberInputs fibers{scene.fiber_scalars, scene.selection_bits, 0};
  fibers.fiber_count = settings.pipeline == RenderPipeline::Compute ? layout_.fibers : scene.raw->streamlineCount();
  recordShade(cmd, shade_pass_, targets_, settings, &timer_, fibers);
}

FrameStats FrameRenderer::collect() {
  FrameStats stats = pending_;
  if (cull_stats_pending_) {
    const CullStats cull = readCullStats(context_, cull_buffers_);
    stats.fiblets_drawn = cull.full();
    stats.fiblets_lod = cull.lod();
  }
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
