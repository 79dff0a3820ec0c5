// The cull passes of the compute pipeline (DESIGN.md section 6, step 1):
// the dilated-frustum test and far-view LoD (CullingMode::Frustum), and the
// conservative two-phase occlusion culling (CullingMode::TwoPhase). Shaders:
// fiblet_cull.comp, fiblet_list_finalize.comp, depth_pyramid.comp,
// fiblet_lod_raster.comp; the arithmetic and the argument that no visible
// fiblet is culled are in shaders/shared/cull_push.h.
//
// Unlike the other pass files this one also records the whole culled raster
// (recordCulledRaster): its passes need a dozen barriers of their own
// (transfer resets of the list counters, indirect reads, the pyramid's
// levels), and keeping them here leaves the frame renderer one call.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu_dataset.h"
#include "render/gpu_fiblet_passes.h"
#include "render/gpu_frame_targets.h"
#include "render/render_settings.h"

namespace fibscope {

struct CullPasses {
  gpu::ComputePipeline cull;        // fiblet_cull.comp
  gpu::ComputePipeline finalize;    // fiblet_list_finalize.comp
  gpu::ComputePipeline pyramid;     // depth_pyramid.comp
  gpu::ComputePipeline lod_raster;  // fiblet_lod_raster.comp
};

CullPasses createCullPasses(const gpu::VulkanContext& context);
void destroyCullPasses(const gpu::VulkanContext& context, CullPasses& passes);

// Scratch that lives across frames. The visible bits are the two-phase
// history: bit f of word f / 32 is set when fiblet f passed the occlusion
// test of the last frame.
struct CullBuffers {
  gpu::Buffer list;      // FibletListHeader + uint per fiblet (full detail), indirect
  gpu::Buffer lod_list;  // FibletListHeader + uint per fiblet (LoD), indirect
  gpu::Buffer visible;   // uint per 32 fiblets, rounded up to 64 fiblets
  gpu::Buffer pyramid;   // float, every level (pyramidLevelOffset)
  gpu::Buffer stats;     // readback: uint[4] = full / LoD counts of phase 1 (or the only phase), phase 2
  uint32_t fiblet_capacity = 0;
  uint32_t width = 0, height = 0;  // of the pyramid
  // The visible bits describe the last frame of this dataset (by its block
  // address) drawn with TwoPhase at this size; otherwise the next TwoPhase
  // frame marks every fiblet visible first.
  bool history_valid = false;
  VkDeviceAddress history_dataset = 0;
};

// Makes the buffers fit `fiblets` fiblets and a width x height frame,
// reallocating what is too small (lists, bits) or of another size
// (pyramid); either invalidates the history. Throws Error when memory runs
// out (the buffers are then released).
void prepareCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers, uint32_t fiblets, uint32_t width,
                        uint32_t height);
void destroyCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers);

// The max-depth pyramid of frame.visibility into buffers.pyramid (which
// prepareCullBuffers sized for the frame): every level, one dispatch each,
// with a barrier between levels; the caller makes the visibility writes
// visible before and places the barrier after.
void recordDepthPyramid(VkCommandBuffer cmd, const CullPasses& passes, const GpuFrameTargets& frame,
                        const CullBuffers& buffers);

// What recordCulledRaster needs besides the buffers.
struct CullFrame {
  CullingMode mode = CullingMode::Frustum;  // Frustum or TwoPhase
  float lod_pixels = 0;                     // 0: no LoD
  float focal_px = 0;                       // cullFocalPixels(camera)
};

// |P[1][1]| * height / 2: a length l at view distance z projects to
// l * focal / z pixels.
float cullFocalPixels(const Camera& camera);

// Records the culled decode + raster into frame.visibility (cleared by the
// caller, camera block written, both made visible to compute), with
// timestamps per pass on `timer` and barriers between its passes; ends with
// the raster's compute writes (the caller's barrier before the resolve
// covers them) and the statistics copied for readCullStats. TwoPhase
// starts from "every fiblet visible" when the history is not valid (first
// frame, new size or dataset, a frame of another mode in between): phase 1
// then draws everything in the frustum and phase 2 learns the true bits at
// once, whereas starting from "none visible" would draw the same in phase 2
// against an empty pyramid and learn nothing until the next frame.
//   Frustum:  cull -> finalize -> raster + LoD raster.
//   TwoPhase: phase-1 cull -> finalize -> raster + LoD raster -> depth
//             pyramid -> phase-2 cull -> finalize -> raster + LoD raster.
void recordCulledRaster(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                        const FibletPasses& fiblet_passes, const GpuDataset& dataset, const GpuFrameTargets& frame,
                        CullBuffers& buffers, const CullFrame& cull, gpu::GpuTimer& timer);

// The fiblets drawn by the last recorded frame, once it has completed.
struct CullStats {
  uint64_t phase1_full = 0, phase1_lod = 0;  // Frustum: the only phase
  uint64_t phase2_full = 0, phase2_lod = 0;
  uint64_t full() const { return phase1_full + phase2_full; }
  uint64_t lod() const { return phase1_lod + phase2_lod; }
};
CullStats readCullStats(const gpu::VulkanContext& context, const CullBuffers& buffers);

}  // namespace fibscope
