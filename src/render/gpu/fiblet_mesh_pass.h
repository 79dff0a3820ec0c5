// The mesh-shader fiblet pipelines (DESIGN.md section 6 "mesh"; the
// fiblets paper, 3.3 and table 2's "mesh (1 thread)"; shaders and meshlet
// layout: shaders/shared/fiblet_mesh.h). VK_EXT_mesh_shader only: where
// the device lacks it nothing is created and the pipelines are refused in
// one line.
//   Mesh:        fiblet_mesh.task + fiblet_mesh.mesh + fiblet_lines.frag
//   MeshSerial:  fiblet_mesh.task + fiblet_mesh_serial.mesh + fiblet_lines.frag
// The task shader culls (the compute cull's tests, shared GLSL) and
// launches one mesh workgroup per survivor; the meshlets are drawn by the
// device's line rasteriser into the line attachments (line_attachments.h)
// and copied into the G-buffer with the geometry pipeline's texel (same
// fragment shader), so shading and picking work unchanged. One
// vkCmdDrawMeshTasksEXT per dataset of ceil(fiblets / 32) task workgroups
// (no indirect arguments: the task shader's own cull sizes the mesh grid).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>

#include "gpu/graphics_pipeline.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/line_attachments.h"
#include "render/gpu/scene_table.h"
#include "render/render_settings.h"

namespace fibscope {

struct FibletMeshPass {
  RenderPipeline kind = RenderPipeline::Mesh;  // Mesh or MeshSerial
  gpu::GraphicsPipeline pipeline;
  LineAttachments attachments;  // none until the first frame
};

// Empty when the device can run the pipeline of `kind`, else the one-line
// reason, e.g. "render: the mesh pipeline needs VK_EXT_mesh_shader, which
// is not supported by llvmpipe (...) (use the compute pipeline)"; also a
// missing graphics queue, gl_ClipDistance, or a mesh/task limit below what
// the shaders declare.
std::string fibletMeshRefusal(const gpu::VulkanContext& context, RenderPipeline kind);

// Throws Error (fibletMeshRefusal's line) where the device cannot run it.
FibletMeshPass createFibletMeshPass(const gpu::VulkanContext& context, RenderPipeline kind);
void destroyFibletMeshPass(const gpu::VulkanContext& context, FibletMeshPass& pass);

// What the task shader culls with.
struct FibletMeshCull {
  bool draw_all = true;  // no test: every fiblet (CullingMode::None without a filter)
  uint32_t mode = 0;     // shader::kCull* otherwise
  float lod_pixels = 0;  // far-view LoD below this (0: off)
  float focal_px = 0;    // cullFocalPixels
  VkDeviceAddress kept_bits = 0;
  // The visible bits, the pyramid and the counters of the statistics
  // (null with draw_all).
  const CullBuffers* buffers = nullptr;
};

// Clears the attachments (of the frame's size: ensureLineAttachments), or
// with `resume` keeps what the last call left (two-phase's second phase),
// draws every dataset of `scene` through the task shader and copies the
// colour attachment into frame.gbuffer (written at the TRANSFER stage when
// this returns). The camera block, the cull's buffers and the mesh cuts'
// tiles must be visible to the task and mesh stages. Throws Error before
// recording anything when a dataset needs more task workgroups than the
// device allows.
void recordFibletMesh(VkCommandBuffer cmd, const gpu::VulkanContext& context, FibletMeshPass& pass,
                      const SceneLayout& scene, const GpuFrameTargets& frame, const FibletMeshCull& cull,
                      float line_width_px, bool resume = false);

// The shader stages the pipelines read buffers in (for barriers).
inline constexpr VkPipelineStageFlags2 kFibletMeshShaderStages = VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT |
                                                                  VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT |
                                                                  VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;

}  // namespace fibscope
