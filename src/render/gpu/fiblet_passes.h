// The compute pipeline's decode + raster and resolve passes (DESIGN.md
// section 6, steps 2 and 3): shaders/fiblet_raster.comp and
// shaders/fiblet_resolve.comp, and the functions that record them. The cull
// passes that feed the raster a list live in cull_passes.h.
//
// Recording functions bind, push and dispatch only; the caller (the frame
// renderer) places the barriers between passes and the timestamps.
#pragma once

#include <vulkan/vulkan.h>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/dataset.h"
#include "render/gpu/frame_targets.h"

namespace fibscope {

struct FibletPasses {
  gpu::ComputePipeline raster;   // fiblet_raster.comp
  gpu::ComputePipeline resolve;         // fiblet_resolve.comp, tangents from the rasters' cache
  gpu::ComputePipeline resolve_decode;  // the same decoding the tangents (frames without a cache)
  uint32_t raster_lanes = 0;     // invocations per fiblet in the raster
  uint32_t raster_fiblets_per_group = 1;  // fiblets per raster workgroup
  bool raster_subgroup_scan = false;      // fiblet_raster_subgroup.comp (else fiblet_raster.comp)
};

// How the raster scans a fiblet's runs: by subgroup shuffles where the lanes
// per fiblet tile a subgroup (subgroup size a multiple of the lanes) and the
// device has relative shuffles (Auto), or in shared memory with barriers
// (any subgroup size).
enum class RasterScan : uint8_t { Auto, SharedMemory, Subgroup };

// The raster's invocations per fiblet for a device: 8 where a subgroup scan
// fits (each lane decodes 8 points; several fiblets per subgroup on GPUs),
// else its subgroup size clamped to [8, 64].
uint32_t defaultRasterLanes(const gpu::VulkanContext& context);

// `raster_lanes`: 8, 16, 32 or 64; 0 = defaultRasterLanes. Throws Error for
// other values, for RasterScan::Subgroup where the device cannot (lanes not
// dividing its subgroup size, no relative shuffles), or when a pipeline
// cannot be created.
FibletPasses createFibletPasses(const gpu::VulkanContext& context, uint32_t raster_lanes = 0,
                                RasterScan scan = RasterScan::Auto);
void destroyFibletPasses(const gpu::VulkanContext& context, FibletPasses& passes);

// Every fiblet of the dataset, one workgroup each. `fiblet_base`: the
// dataset's first fiblet in the scene's numbering (render/gpu/scene_table.h;
// 0 for a dataset drawn alone), which the keys and the tangent cache use.
void recordFibletRasterAll(VkCommandBuffer cmd, const gpu::VulkanContext& context, const FibletPasses& passes,
                           const GpuDataset& dataset, const GpuFrameTargets& frame, uint32_t fiblet_base = 0);
// The fiblets of the list at `list_offset` in `list` (shared/fiblet_list.h;
// the dataset's own fiblet indices), dispatched indirectly from the list's
// header; the list must have been finalised (dispatch size written) and
// made visible to indirect reads.
void recordFibletRasterList(VkCommandBuffer cmd, const FibletPasses& passes, const GpuDataset& dataset,
                            const GpuFrameTargets& frame, const gpu::Buffer& list, VkDeviceSize list_offset = 0,
                            uint32_t fiblet_base = 0);
// Every pixel: the winning key's global fiblet -> its dataset through the
// scene table at `scene_table` (shared/scene_table.h, made visible to
// compute) -> the G-buffer texel with the global fiber.
void recordFibletResolve(VkCommandBuffer cmd, const FibletPasses& passes, VkDeviceAddress scene_table,
                         const GpuFrameTargets& frame);

// Workgroups of kPixelGroupSize^2 covering the frame.
uint32_t pixelGroupsX(const GpuFrameTargets& frame);
uint32_t pixelGroupsY(const GpuFrameTargets& frame);

}  // namespace fibscope
