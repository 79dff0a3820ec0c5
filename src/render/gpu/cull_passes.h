// The cull passes of the compute pipeline (DESIGN.md section 6, step 1):
// the dilated-frustum test and far-view LoD (CullingMode::Frustum), and the
// conservative two-phase occlusion culling (CullingMode::TwoPhase), and the
// paper's coverage buffer (CullingMode::Coverage, coverage_pass.h). Shaders:
// fiblet_cull.comp, fiblet_list_finalize.comp, depth_pyramid.comp,
// fiblet_lod_raster.comp, coverage_reproject.comp; the arithmetic and the
// argument that two-phase culls no visible fiblet are in
// shaders/shared/cull_push.h (coverage's, which may: shared/coverage_push.h).
//
// Unlike the other pass files this one also records the whole culled raster
// (recordCulledRaster): its passes need a dozen barriers of their own
// (transfer resets of the list counters, indirect reads, the pyramid's
// levels), and keeping them here leaves the frame renderer one call.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu/coverage_pass.h"
#include "shared/coverage_push.h"
#include "render/gpu/dataset.h"
#include "render/gpu/fiblet_passes.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/scene_table.h"
#include "render/render_settings.h"

namespace fibscope {

struct CullPasses {
  gpu::ComputePipeline cull;        // fiblet_cull.comp
  gpu::ComputePipeline finalize;    // fiblet_list_finalize.comp
  gpu::ComputePipeline pyramid;     // depth_pyramid.comp
  gpu::ComputePipeline lod_raster;  // fiblet_lod_raster.comp
  gpu::ComputePipeline coverage;    // coverage_reproject.comp
};

CullPasses createCullPasses(const gpu::VulkanContext& context);
// fiblet_list_finalize.comp (one invocation: it turns a list's count into
// its indirect dispatch), which the tile list of the shading uses too.
gpu::ComputePipeline createListFinalizePipeline(const gpu::VulkanContext& context);
void destroyCullPasses(const gpu::VulkanContext& context, CullPasses& passes);

// Where one drawn dataset's lists and visible bits lie in CullBuffers.
// Each dataset of a scene is culled and drawn by dispatches of its own
// (the pushes name one dataset block), into lists of its own: regions of
// the shared list buffers, so the culls of all datasets run back to back
// without barriers between them and each indirect raster reads its region.
struct CullRegion {
  VkDeviceSize list_offset = 0;     // of its FibletListHeader in list and lod_list (16-byte aligned)
  VkDeviceSize visible_offset = 0;  // of its first bit word in visible (whole kCullGroupSize groups)
  uint32_t fiblets = 0;
};

// Scratch that lives across frames. The visible bits are the two-phase
// history: bit f of word f / 32 of a dataset's region is set when its
// fiblet f passed the occlusion test of the last frame.
struct CullBuffers {
  gpu::Buffer list;      // per region: FibletListHeader + uint per fiblet (full detail), indirect
  gpu::Buffer lod_list;  // per region: FibletListHeader + uint per fiblet (LoD), indirect
  gpu::Buffer visible;   // per region: uint per 32 fiblets, rounded up to 64 fiblets
  gpu::Buffer pyramid;   // float, every level (pyramidLevelOffset)
  // readback: uint[4] per region = full / LoD counts of phase 1 (or the
  // only phase), phase 2
  gpu::Buffer stats;
  std::vector<CullRegion> regions;  // of the last prepareCullBuffers
  VkDeviceSize list_capacity = 0, visible_capacity = 0;  // bytes
  uint32_t width = 0, height = 0;  // of the pyramid
  // The visible bits describe the last frame of this scene (by its
  // datasets' block addresses and counts, sameScene) drawn with TwoPhase at
  // this size; otherwise the next TwoPhase frame marks every fiblet visible
  // first.
  bool history_valid = false;
  SceneLayout history_scene;
  // CullingMode::Coverage: the last Coverage frame's keys and camera
  // (sized with the pyramid; a new size drops it).
  CoverageHistory coverage;
};

// Makes the buffers fit datasets of `dataset_fiblets` fiblets (one region
// each, in order; at most kMaxSceneDatasets) and a width x height frame,
// reallocating what is too small (lists, bits) or of another size
// (pyramid); either invalidates the history. Throws Error when memory runs
// out (the buffers are then released). `coverage`: also the coverage
// history's keys (only Coverage frames need them).
void prepareCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers,
                        std::span<const uint32_t> dataset_fiblets, uint32_t width, uint32_t height,
                        bool coverage = false);
// One dataset.
void prepareCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers, uint32_t fiblets, uint32_t width,
                        uint32_t height, bool coverage = false);
void destroyCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers);

// The max-depth pyramid of frame.visibility into buffers.pyramid (which
// prepareCullBuffers sized for the frame): every level, one dispatch each,
// with a barrier between levels; the caller makes the visibility writes
// visible before and places the barrier after. first_level 1: level 0 is
// already there (Coverage writes it), the levels above are built from it.
// With `from_gbuffer`, level 0 is frame.gbuffer's depths instead of the
// visibility buffer's (the graphics fiblet pipelines).
void recordDepthPyramid(VkCommandBuffer cmd, const CullPasses& passes, const GpuFrameTargets& frame,
                        const CullBuffers& buffers, uint32_t first_level = 0, bool from_gbuffer = false);

// What recordCulledRaster needs besides the buffers.
struct CullFrame {
  // Frustum, TwoPhase or Coverage; None: no test but the fiber filter's
  // (every fiblet of a kept fiber drawn at full detail).
  CullingMode mode = CullingMode::Frustum;
  float lod_pixels = 0;                     // 0: no LoD
  float focal_px = 0;                       // cullFocalPixels(camera)
  VkDeviceAddress kept_bits = 0;            // GpuScene::kept_bits: the filter's fibers only; 0: all
  // The frame's camera (Coverage re-projects the last frame into it and
  // keeps it for the next).
  Camera camera;
  float coverage_splat_px = shader::kCoverageSplatPixels;  // Coverage: k of R_S(z)
};

// |P[1][1]| * height / 2: a length l at view distance z projects to
// l * focal / z pixels.
float cullFocalPixels(const Camera& camera);

// Records the culled decode + raster of every dataset of `scene` (regions
// prepared by prepareCullBuffers for its datasets' fiblet counts, in
// order) into frame.visibility (cleared by the caller, camera block
// written, both made visible to compute), each pass in a gpu::PassScope on
// `timer` (may be null); the raster's writes are visible to later compute
// passes when it returns, and the statistics copied for readCullStats. TwoPhase
// starts from "every fiblet visible" when the history is not valid (first
// frame, new size or scene, a frame of another mode in between): phase 1
// then draws everything in the frustum and phase 2 learns the true bits at
// once, whereas starting from "none visible" would draw the same in phase 2
// against an empty pyramid and learn nothing until the next frame.
// Several datasets share each phase: all culls, all finalizes, all rasters,
// and one pyramid of everything phase 1 drew, so a fiber of one model
// occludes the fiblets of another.
//   Frustum:  cull -> finalize -> raster + LoD raster.
//   TwoPhase: phase-1 cull -> finalize -> raster + LoD raster -> depth
//             pyramid -> phase-2 cull -> finalize -> raster + LoD raster.
//   Coverage: coverage (the last Coverage frame's keys re-projected into
//             the pyramid's level 0, then its other levels) -> cull ->
//             finalize -> raster + LoD raster -> the keys kept. Without a
//             valid history (first frame, new size or scene, a frame of
//             another mode in between) the cull is Frustum's.
void recordCulledRaster(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                        const FibletPasses& fiblet_passes, const SceneLayout& scene, const GpuFrameTargets& frame,
                        CullBuffers& buffers, const CullFrame& cull, gpu::GpuTimer* timer);

// The cull alone, for pipelines that draw its lists themselves (the
// geometry and tessellation fiblet pipelines, which turn each region's
// full-detail list into an indirect draw): every region's counters reset,
// then every dataset's cull in `cull.mode` (Frustum or None, the fiber
// filter only; the lists' writes visible to later compute passes when it
// returns). LoD goes to the LoD list, which these pipelines do not draw:
// cull.lod_pixels must be 0. The two-phase history is invalidated.
// TwoPhase: `phase` 1 (the history reset first where it is not valid, as
// recordCulledRaster does), then after the caller's draw and
// recordDepthPyramid, phase 2 (which records the history).
void recordCullLists(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                     const SceneLayout& scene, const GpuFrameTargets& frame, CullBuffers& buffers,
                     const CullFrame& cull, uint32_t phase = 0);
// For pipelines that cull in a stage of their own (the mesh pipelines' task
// shader, which only adds to the lists' counts): what recordCullLists does
// before its culls (the counters reset, the statistics too in phases 0
// and 1, the visible bits set where the two-phase history is not valid in
// phase 1), made visible to `consumers` (shader reads and writes); then
// their draws, then recordCullListStats, and markCullHistory after each.
void recordCullCountersReset(VkCommandBuffer cmd, CullBuffers& buffers, const SceneLayout& scene, uint32_t phase,
                             VkPipelineStageFlags2 consumers);
// The two-phase history valid after phase 2 (recording `scene`), invalid
// after any other phase.
void markCullHistory(CullBuffers& buffers, const SceneLayout& scene, uint32_t phase);
// After recordCullLists and the draws that read its lists (their reads
// before this with a barrier of the caller's): the counts copied for
// readCullStats (phase 2: into the second phase's slots).
void recordCullListStats(VkCommandBuffer cmd, const CullBuffers& buffers, uint32_t phase = 0);

// The checks of a pipeline that draws fiblets as hardware lines (geometry,
// tessellation, mesh, mesh-serial): it needs fiblets (`has_fiblets`), and
// takes culling none, frustum or two-phase (the coverage buffer re-projects
// the compute pipeline's visibility keys). Throws Error naming `kind`.
void checkFibletLinePipeline(RenderPipeline kind, const RenderSettings& settings, bool has_fiblets);

// The fiblets drawn by the last recorded frame (summed over its datasets),
// once it has completed.
struct CullStats {
  uint64_t phase1_full = 0, phase1_lod = 0;  // Frustum: the only phase
  uint64_t phase2_full = 0, phase2_lod = 0;
  uint64_t full() const { return phase1_full + phase2_full; }
  uint64_t lod() const { return phase1_lod + phase2_lod; }
};
CullStats readCullStats(const gpu::VulkanContext& context, const CullBuffers& buffers);
// A culled frame's fiblets_drawn and fiblets_lod from readCullStats.
void collectCullStats(const gpu::VulkanContext& context, const CullBuffers& buffers, FrameStats& stats);

}  // namespace fibscope
