#include "render/gpu/fiblet_mesh_pass.h"

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/gpu/dataset.h"
#include "render/gpu/lines_pass.h"
#include "shared/camera.h"
#include "shared/fiblet_mesh.h"

namespace fibscope {
namespace {

using shader::kMeshLanes;
using shader::kMeshMaxPrimitives;
using shader::kMeshMaxVertices;
using shader::kMeshTaskGroupSize;

uint32_t roundUp(uint32_t n, uint32_t granularity) {
  return granularity == 0 ? n : (n + granularity - 1) / granularity * granularity;
}

std::string refusal(const gpu::VulkanContext& context, RenderPipeline kind, const std::string& why) {
  return "render: the " + std::string(renderPipelineName(kind)) + " pipeline needs " + why + ", which " +
         context.info().name + " lacks (use the compute pipeline)";
}

}  // namespace

std::string fibletMeshRefusal(const gpu::VulkanContext& context, RenderPipeline kind) {
  if (!needsMeshShaders(kind)) return "render: fibletMeshRefusal: not a mesh fiblet pipeline";
  if (!context.meshShader().enabled)
    return "render: the " + std::string(renderPipelineName(kind)) +
           " pipeline needs mesh shaders: VK_EXT_mesh_shader not supported by " + context.info().name +
           " (use the compute pipeline)";
  if (!context.info().queue_has_graphics) return refusal(context, kind, "a graphics queue");
  if (!context.enabledFeatures().shaderClipDistance)
    return refusal(context, kind, "gl_ClipDistance (shaderClipDistance)");
  const VkPhysicalDeviceMeshShaderPropertiesEXT& p = context.meshShader().properties;
  // What the shaders declare (shared/fiblet_mesh.h). The EXT's minimum
  // guarantees cover all of it (256 vertices and primitives, 128
  // invocations, 16 KiB of payload, 28 KiB of shared memory, 32 KiB of
  // output); checked all the same, as the geometry pipeline checks its
  // limits.
  const uint32_t mesh_invocations = kind == RenderPipeline::Mesh ? kMeshLanes : 1u;
  if (p.maxMeshOutputVertices < kMeshMaxVertices || p.maxMeshOutputPrimitives < kMeshMaxPrimitives)
    return refusal(context, kind,
                   std::to_string(kMeshMaxVertices) + " mesh output vertices and " + std::to_string(kMeshMaxPrimitives) +
                       " primitives");
  if (p.maxMeshWorkGroupInvocations < mesh_invocations || p.maxMeshWorkGroupSize[0] < mesh_invocations)
    return refusal(context, kind, std::to_string(mesh_invocations) + " mesh workgroup invocations");
  if (p.maxTaskWorkGroupInvocations < kMeshTaskGroupSize || p.maxTaskWorkGroupSize[0] < kMeshTaskGroupSize)
    return refusal(context, kind, std::to_string(kMeshTaskGroupSize) + " task workgroup invocations");
  if (p.maxTaskPayloadSize < sizeof(shader::FibletMeshPayload) ||
      p.maxMeshWorkGroupCount[0] < kMeshTaskGroupSize || p.maxMeshWorkGroupTotalCount < kMeshTaskGroupSize)
    return refusal(context, kind, "a task payload of " + std::to_string(sizeof(shader::FibletMeshPayload)) +
                                      " bytes launching " + std::to_string(kMeshTaskGroupSize) + " mesh workgroups");
  // Per vertex: gl_Position, the clip distances and the three flat words
  // (counted in whole vec4 slots, as the spec's output-memory formula may);
  // per line: its two indices, padded likewise.
  constexpr uint32_t kVertexComponents = 4 + shader::kMaxFrameClipPlanes + 3;
  if (p.maxMeshOutputComponents < kVertexComponents)
    return refusal(context, kind, std::to_string(kVertexComponents) + " mesh output components");
  const uint64_t vertex_bytes = 16 * (1 + (shader::kMaxFrameClipPlanes + 3) / 4 + 3);
  const uint64_t output_bytes = uint64_t(roundUp(kMeshMaxVertices, p.meshOutputPerVertexGranularity)) * vertex_bytes +
                                uint64_t(roundUp(kMeshMaxPrimitives, p.meshOutputPerPrimitiveGranularity)) * 16;
  if (p.maxMeshOutputMemorySize < output_bytes)
    return refusal(context, kind, std::to_string(output_bytes) + " bytes of mesh output memory");
  const uint32_t shared_bytes = kind == RenderPipeline::Mesh ? kMeshLanes * 48u : 0u;  // FibletTransform each
  if (p.maxMeshSharedMemorySize < shared_bytes ||
      p.maxMeshPayloadAndSharedMemorySize < shared_bytes + sizeof(shader::FibletMeshPayload))
    return refusal(context, kind, std::to_string(shared_bytes) + " bytes of mesh shared memory");
  return "";
}

FibletMeshPass createFibletMeshPass(const gpu::VulkanContext& context, RenderPipeline kind) {
  if (const std::string why = fibletMeshRefusal(context, kind); !why.empty()) throw Error(why);
  gpu::GraphicsPipelineDesc desc;
  desc.task_shader = "fiblet_mesh.task";
  desc.mesh_shader = kind == RenderPipeline::Mesh ? "fiblet_mesh.mesh" : "fiblet_mesh_serial.mesh";
  desc.fragment_shader = "fiblet_lines.frag";
  desc.color_format = kLineColorFormat;
  desc.depth_format = kLineDepthFormat;
  desc.push_constant_bytes = sizeof(shader::FibletMeshPush);
  desc.dynamic_line_width = true;
  FibletMeshPass pass;
  pass.kind = kind;
  pass.pipeline = gpu::createGraphicsPipeline(context, desc);
  return pass;
}

void destroyFibletMeshPass(const gpu::VulkanContext& context, FibletMeshPass& pass) {
  releaseLineAttachments(context, pass.attachments);
  gpu::destroyGraphicsPipeline(context, pass.pipeline);
}

void recordFibletMesh(VkCommandBuffer cmd, const gpu::VulkanContext& context, FibletMeshPass& pass,
                      const SceneLayout& scene, const GpuFrameTargets& frame, const FibletMeshCull& cull,
                      float line_width_px, bool resume) {
  if (!cull.draw_all && (!cull.buffers || cull.buffers->regions.size() != scene.entries.size()))
    throw Error("render: the mesh pipeline's cull buffers were not prepared for the scene's " +
                std::to_string(scene.entries.size()) + " datasets");
  const VkPhysicalDeviceMeshShaderPropertiesEXT& p = context.meshShader().properties;
  // Task workgroups per dataset, as a grid the device allows (the task
  // shader flattens it: y * width + x).
  struct Grid {
    uint32_t x = 0, y = 0;
  };
  std::vector<Grid> grids;
  for (const SceneEntry& e : scene.entries) {
    const uint64_t groups = (uint64_t(e.fiblets) + kMeshTaskGroupSize - 1) / kMeshTaskGroupSize;
    Grid g;
    if (groups > 0) {
      g.x = uint32_t(std::min<uint64_t>(groups, p.maxTaskWorkGroupCount[0]));
      g.y = uint32_t((groups + g.x - 1) / g.x);
      if (g.y > p.maxTaskWorkGroupCount[1] || uint64_t(g.x) * g.y > p.maxTaskWorkGroupTotalCount)
        throw Error("render: the " + std::string(renderPipelineName(pass.kind)) + " pipeline draws at most " +
                    std::to_string(uint64_t(p.maxTaskWorkGroupTotalCount) * kMeshTaskGroupSize) +
                    " fiblets per dataset on " + context.info().name + ", a dataset has " +
                    std::to_string(e.fiblets));
    }
    grids.push_back(g);
  }
  if (resume)
    resumeLineAttachments(cmd, pass.attachments);
  else
    beginLineAttachments(cmd, pass.attachments);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pass.pipeline.pipeline);
  vkCmdSetLineWidth(cmd, linesDrawnWidth(context, line_width_px));
  // Datasets in scene order, as the geometry pipeline draws them.
  for (size_t i = 0; i < scene.entries.size(); ++i) {
    const SceneEntry& e = scene.entries[i];
    if (e.fiblets == 0) continue;
    shader::FibletMeshPush push{};
    push.cull.dataset = e.dataset->blockAddress();
    push.cull.camera = frame.camera.address;
    push.cull.fiber_base = e.fiber_base;
    push.draw_all = cull.draw_all ? 1u : 0u;
    if (!cull.draw_all) {
      const CullBuffers& b = *cull.buffers;
      const CullRegion& region = b.regions[i];
      push.cull.list = b.list.address + region.list_offset;
      push.cull.lod_list = b.lod_list.address + region.list_offset;
      push.cull.visible = b.visible.address + region.visible_offset;
      push.cull.pyramid = b.pyramid.address;
      push.cull.kept = cull.kept_bits;
      push.cull.mode = cull.mode;
      push.cull.lod_pixels = cull.lod_pixels;
      push.cull.focal_px = cull.focal_px;
    }
    vkCmdPushConstants(cmd, pass.pipeline.layout, pass.pipeline.stages, 0, sizeof(push), &push);
    context.meshShader().cmdDrawMeshTasks(cmd, grids[i].x, grids[i].y, 1);
  }
  endLineAttachmentsIntoGBuffer(cmd, pass.attachments, frame);
}

}  // namespace fibscope
