// Exact per-fiblet bounding spheres (shaders/fiblet_bounds.comp), computed
// once per dataset (in the first frame that culls by occlusion, see
// render/gpu/dataset.h) and read by the cull
// (fiblet_cull.comp) through FibletDataset::fiblet_bounds.
//
// Why: the record alone only bounds a fiblet by a sphere around its first
// point whose radius is the whole fiblet's length (plus the joining
// segment, whose length the format does not bound), about twice the radius
// of a sphere around the fiblet's middle; the occlusion test's screen
// rectangle grows with the square of that. Decoding every fiblet once
// gives the tight sphere for 16 bytes per fiblet.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"

namespace fibscope {

// Bytes of the bounds buffer per fiblet: one vec4 (world centre, radius).
inline constexpr uint64_t kFibletBoundsBytes = 16;

struct FibletBoundsPass {
  gpu::ComputePipeline bounds;  // fiblet_bounds.comp
};

FibletBoundsPass createFibletBoundsPass(const gpu::VulkanContext& context);
void destroyFibletBoundsPass(const gpu::VulkanContext& context, FibletBoundsPass& pass);

// Records the pass: one invocation per fiblet of the dataset whose block is
// at `dataset` (its records and direction table written and visible to
// compute shaders) writes `fiblets` vec4 to `bounds` (16-byte aligned). The
// caller places the barrier before the cull reads them.
void recordFibletBounds(VkCommandBuffer cmd, const gpu::VulkanContext& context, const FibletBoundsPass& pass,
                        VkDeviceAddress dataset, VkDeviceAddress bounds, uint32_t fiblets);

// Creates the pipeline, computes the bounds in one submission (after a
// barrier from earlier transfers), waits and destroys the pipeline
// (GpuDataset::computeFibletBounds). Throws Error when the device is lost.
void computeFibletBounds(const gpu::VulkanContext& context, VkDeviceAddress dataset, VkDeviceAddress bounds,
                         uint32_t fiblets);

}  // namespace fibscope
