// The paper's comparison pipelines (Schertzer et al. 2022, section 4.5,
// table 2): the compute pipeline's fiblets and cull, decoded in a graphics
// stage and drawn as lines by the device's line rasteriser into the line
// attachments (line_attachments.h), then copied into the G-buffer like the
// lines baseline, with the same texel the compute resolve writes (fiber
// fiber_base + fiblet_fiber, segment = the point index within the fiblet,
// the segment's packed tangent), so shading and picking work unchanged.
//   geometry:     fiblet_lines.vert + .geom + .frag: one point per fiblet,
//                 the geometry shader decodes serially and emits a line
//                 strip of up to 61 vertices.
//   tessellation: fiblet_lines.vert + .tesc + .tese + .frag: one-vertex
//                 patches, the tessellator makes one isoline of up to 60
//                 segments per fiblet, the evaluation stage decodes each
//                 vertex's point from the fiblet's start (why: the shaders'
//                 headers).
// One draw per dataset: vkCmdDraw of every fiblet, or, culled, one
// vkCmdDrawIndirect per dataset whose arguments fiblet_draw_args.comp
// writes from the cull list's count (the vertex shader reads the list).
// Except tessellation on CPU devices: lavapipe (Mesa 22.3) hands the
// control and evaluation stages another patch's inputs in draws of many
// patches (measured: a 400-fiber phantom drew half its pixels, or segments
// joining unrelated fiblets; drawn in draws of 64 patches, it matches the
// lines baseline, and 25 times faster), so there each draw covers at most
// kCpuTessellationPatchesPerDraw fiblets: several vkCmdDraw, or one
// multi-draw vkCmdDrawIndirect of several commands.
// Line rasterisation differs from the compute rasters' capsule rule by up
// to about a pixel (see lines_pass.h); the tests measure by how much.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/graphics_pipeline.h"
#include "gpu/tessellation_draws.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/line_attachments.h"
#include "render/gpu/scene_table.h"
#include "render/render_settings.h"

namespace fibscope {

struct FibletGraphicsPass {
  RenderPipeline kind = RenderPipeline::Geometry;  // Geometry or Tessellation
  gpu::GraphicsPipeline pipeline;
  gpu::ComputePipeline draw_args;  // fiblet_draw_args.comp
  gpu::Buffer args;                // the draw commands (ensureFibletDrawArgs)
  LineAttachments attachments;     // none until the first frame
  uint32_t patches_per_draw = 0;   // 0: no cap (see above)
  // Per scene entry, its first command in `args` and how many (one without
  // a cap, else one per patches_per_draw fiblets of the dataset).
  std::vector<uint32_t> command_first, command_count;
};

inline constexpr uint32_t kCpuTessellationPatchesPerDraw = gpu::kCpuTessellationPatchesPerDraw;

// The pipeline of `kind` (Geometry or Tessellation). Throws Error (one
// line) when the device lacks a graphics queue, the stage's feature
// (geometryShader, tessellationShader), gl_ClipDistance, or the limits the
// shaders need (61 geometry output vertices and their components; a
// tessellation level of 60).
FibletGraphicsPass createFibletGraphicsPass(const gpu::VulkanContext& context, RenderPipeline kind);
void destroyFibletGraphicsPass(const gpu::VulkanContext& context, FibletGraphicsPass& pass);

// The draw commands of `scene`'s datasets: `args` grown when too small
// (after waiting for the device), command_first / command_count set.
void ensureFibletDrawArgs(const gpu::VulkanContext& context, FibletGraphicsPass& pass, const SceneLayout& scene);

// Culled frames (after ensureFibletDrawArgs for the scene): each region's draw arguments from its full-detail list
// (recordCullLists before, its writes visible to compute); the arguments
// and lists are visible to the draws when this returns.
void recordFibletDrawArgs(VkCommandBuffer cmd, const FibletGraphicsPass& pass, const CullBuffers& buffers);

// Clears the attachments (of the frame's size: ensureLineAttachments),
// draws every dataset of `scene` (every fiblet when `culled` is null, else
// the region's list through the arguments recordFibletDrawArgs wrote) and
// copies the colour attachment into frame.gbuffer (written at the TRANSFER
// stage when this returns). The camera block must be visible to the
// pre-rasterisation stages.
void recordFibletGraphics(VkCommandBuffer cmd, const gpu::VulkanContext& context, FibletGraphicsPass& pass,
                          const SceneLayout& scene, const GpuFrameTargets& frame, const CullBuffers* culled,
                          float line_width_px, bool resume = false);
// `resume`: over what the last call left (resumeLineAttachments) instead
// of cleared: two-phase culling's second phase.

// The shader stages the pipeline of `kind` reads buffers in (for barriers).
VkPipelineStageFlags2 fibletGraphicsShaderStages(RenderPipeline kind);

}  // namespace fibscope
