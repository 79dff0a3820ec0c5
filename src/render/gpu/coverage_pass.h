// The coverage-buffer pass of CullingMode::Coverage (the fiblets paper's
// occlusion culling, section 3.4 and appendix C; DESIGN.md section 6):
// coverage_reproject.comp splats the previous frame's covered pixels into
// the new frame as carved hemispheres of radius R_S(z). The method, the
// radius and why it is not conservative: shaders/shared/coverage_push.h.
// recordCulledRaster (cull_passes.h) records it before the cull, then the
// max-mip pyramid of its output, and keeps the history at the frame's end.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/scene_table.h"
#include "shared/coverage_push.h"

namespace fibscope {

// What a Coverage frame keeps for the next: its visibility keys (a copy of
// the frame's, same layout) and its camera. `valid` only while the next
// frame can re-project it: the same size (prepareCullBuffers drops it on a
// resize), the same scene (`scene`) and no frame of another mode or
// pipeline in between (the fiblet stage drops it then).
struct CoverageHistory {
  gpu::Buffer previous_keys;  // uint64_t per visibility key of the last Coverage frame
  Camera camera;              // its camera
  SceneLayout scene;
  bool valid = false;
};

gpu::ComputePipeline createCoveragePipeline(const gpu::VulkanContext& context);

// Makes history.previous_keys hold a width x height frame's keys (and drops
// the history) when it does not already. Throws Error when memory runs out.
void prepareCoverageHistory(const gpu::VulkanContext& context, CoverageHistory& history, uint32_t width,
                            uint32_t height);
void destroyCoverageHistory(const gpu::VulkanContext& context, CoverageHistory& history);

// The world radius R_S of a sample at view depth `view_depth_mm` of a frame
// seen by `camera`, `splat_pixels` of its pixels (shared/coverage_push.h:
// coverageSplatRadius).
float coverageSplatRadiusMm(const Camera& camera, float view_depth_mm,
                            float splat_pixels = shader::kCoverageSplatPixels);

// Splats history.previous_keys (seen by history.camera) into `coverage`:
// a uint per pixel of `frame` (row-major), which the caller cleared to
// kCoverageFarBits and made visible to compute; frame.camera holds the new
// camera `camera`, visible to compute. The caller places the barrier after.
// Both frames are frame.width x frame.height. `splat_pixels`: k of R_S(z).
void recordCoverageReproject(VkCommandBuffer cmd, const gpu::ComputePipeline& pipeline, const CoverageHistory& history,
                             const Camera& camera, const GpuFrameTargets& frame, VkDeviceAddress coverage,
                             float splat_pixels = shader::kCoverageSplatPixels);

}  // namespace fibscope
