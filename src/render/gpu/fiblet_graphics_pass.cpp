#include "render/gpu/fiblet_graphics_pass.h"

#include <algorithm>
#include <string>

#include "core/error.h"
#include "gpu/submit.h"
#include "render/gpu/dataset.h"
#include "render/gpu/lines_pass.h"
#include "shared/camera.h"
#include "shared/fiblet.h"
#include "shared/render_push.h"
#include "shared/scene_table.h"

namespace fibscope {
namespace {

// The shaders' fixed sizes (fiblet_lines.geom, fiblet_lines.tesc).
constexpr uint32_t kGeometryVertices = shader::kFibletMaxPoints + 1;  // + the joining vertex
// Per geometry output vertex: gl_Position, the clip distances and the three
// flat words, counted as a driver may (built-ins included).
constexpr uint32_t kGeometryComponents = 4 + shader::kMaxFrameClipPlanes + 3;
constexpr uint32_t kTessSegments = shader::kFibletMaxPoints;  // used + the joining segment

std::string refusal(const gpu::VulkanContext& context, RenderPipeline kind, const std::string& why) {
  return "render: the " + std::string(renderPipelineName(kind)) + " pipeline needs " + why + ", which " +
         context.info().name + " lacks (use the compute pipeline)";
}

void checkDevice(const gpu::VulkanContext& context, RenderPipeline kind) {
  if (!context.info().queue_has_graphics) throw Error(refusal(context, kind, "a graphics queue"));
  const VkPhysicalDeviceFeatures& f = context.enabledFeatures();
  const VkPhysicalDeviceLimits& l = context.limits();
  if (!f.shaderClipDistance) throw Error(refusal(context, kind, "gl_ClipDistance (shaderClipDistance)"));
  if (kind == RenderPipeline::Geometry) {
    if (!f.geometryShader) throw Error(refusal(context, kind, "geometry shaders (geometryShader)"));
    if (l.maxGeometryOutputVertices < kGeometryVertices)
      throw Error(refusal(context, kind, std::to_string(kGeometryVertices) + " geometry output vertices"));
    if (l.maxGeometryTotalOutputComponents < kGeometryVertices * kGeometryComponents ||
        l.maxGeometryOutputComponents < kGeometryComponents)
      throw Error(refusal(context, kind,
                          std::to_string(kGeometryVertices * kGeometryComponents) + " geometry output components"));
  } else {
    if (!f.tessellationShader) throw Error(refusal(context, kind, "tessellation shaders (tessellationShader)"));
    if (l.maxTessellationGenerationLevel < kTessSegments)
      throw Error(refusal(context, kind, "tessellation level " + std::to_string(kTessSegments)));
  }
}

}  // namespace

VkPipelineStageFlags2 fibletGraphicsShaderStages(RenderPipeline kind) {
  return kind == RenderPipeline::Tessellation
             ? VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT |
                   VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT
             : VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT |
                   VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
}

FibletGraphicsPass createFibletGraphicsPass(const gpu::VulkanContext& context, RenderPipeline kind) {
  if (kind != RenderPipeline::Geometry && kind != RenderPipeline::Tessellation)
    throw Error("render: createFibletGraphicsPass: not a graphics fiblet pipeline");
  checkDevice(context, kind);
  gpu::GraphicsPipelineDesc desc;
  desc.vertex_shader = "fiblet_lines.vert";
  desc.fragment_shader = "fiblet_lines.frag";
  if (kind == RenderPipeline::Geometry) {
    desc.geometry_shader = "fiblet_lines.geom";
    desc.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
  } else {
    desc.tess_control_shader = "fiblet_lines.tesc";
    desc.tess_evaluation_shader = "fiblet_lines.tese";
    desc.topology = VK_PRIMITIVE_TOPOLOGY_PATCH_LIST;
    desc.patch_control_points = 1;
  }
  desc.color_format = kLineColorFormat;
  desc.depth_format = kLineDepthFormat;
  desc.push_constant_bytes = sizeof(shader::FibletDrawPush);
  desc.dynamic_line_width = true;
  FibletGraphicsPass pass;
  pass.kind = kind;
  if (kind == RenderPipeline::Tessellation) pass.patches_per_draw = gpu::tessellationPatchesPerDraw(context);
  try {
    pass.pipeline = gpu::createGraphicsPipeline(context, desc);
    pass.draw_args =
        gpu::createComputePipeline(context, "fiblet_draw_args.comp", sizeof(shader::FibletDrawArgsPush));
  } catch (...) {
    destroyFibletGraphicsPass(context, pass);
    throw;
  }
  return pass;
}

void destroyFibletGraphicsPass(const gpu::VulkanContext& context, FibletGraphicsPass& pass) {
  releaseLineAttachments(context, pass.attachments);
  gpu::destroyBuffer(context, pass.args);
  gpu::destroyComputePipeline(context, pass.draw_args);
  gpu::destroyGraphicsPipeline(context, pass.pipeline);
}

void ensureFibletDrawArgs(const gpu::VulkanContext& context, FibletGraphicsPass& pass, const SceneLayout& scene) {
  pass.command_first.clear();
  pass.command_count.clear();
  uint64_t total = 0;
  for (const SceneEntry& e : scene.entries) {
    const uint32_t n = pass.patches_per_draw == 0
                           ? 1u
                           : std::max<uint32_t>(1, (e.fiblets + pass.patches_per_draw - 1) / pass.patches_per_draw);
    pass.command_first.push_back(uint32_t(total));
    pass.command_count.push_back(n);
    total += n;
  }
  const VkDeviceSize bytes = std::max<uint64_t>(total, 1) * sizeof(VkDrawIndirectCommand);
  if (pass.args.size >= bytes) return;
  vkDeviceWaitIdle(context.device());  // earlier frames may read them
  gpu::destroyBuffer(context, pass.args);
  pass.args = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
}

void recordFibletDrawArgs(VkCommandBuffer cmd, const FibletGraphicsPass& pass, const CullBuffers& buffers) {
  if (pass.command_first.size() != buffers.regions.size())
    throw Error("render: the draw commands were prepared for " + std::to_string(pass.command_first.size()) +
                " datasets, the cull lists for " + std::to_string(buffers.regions.size()));
  // The previous frame's draws read the arguments (write-after-read).
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, 0, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0);
  shader::FibletDrawArgsPush push{};
  push.chunk = pass.patches_per_draw == 0 ? 0xFFFFFFFFu : pass.patches_per_draw;
  for (size_t i = 0; i < buffers.regions.size(); ++i) {
    push.list = buffers.list.address + buffers.regions[i].list_offset;
    push.args = pass.args.address + uint64_t(pass.command_first[i]) * sizeof(VkDrawIndirectCommand);
    push.commands = pass.command_count[i];
    gpu::recordDispatch(cmd, pass.draw_args, push, (push.commands + 63) / 64);
  }
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT,
                     VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
}

void recordFibletGraphics(VkCommandBuffer cmd, const gpu::VulkanContext& context, FibletGraphicsPass& pass,
                          const SceneLayout& scene, const GpuFrameTargets& frame, const CullBuffers* culled,
                          float line_width_px, bool resume) {
  if (culled && culled->regions.size() != scene.entries.size())
    throw Error("render: the cull lists were prepared for " + std::to_string(culled->regions.size()) +
                " datasets, the scene has " + std::to_string(scene.entries.size()));
  if (resume)
    resumeLineAttachments(cmd, pass.attachments);
  else
    beginLineAttachments(cmd, pass.attachments);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pass.pipeline.pipeline);
  vkCmdSetLineWidth(cmd, linesDrawnWidth(context, line_width_px));
  // Datasets in scene order, so primitive order (and with it the depth
  // test's ties) is that of one draw over the scene's fiblets.
  for (size_t i = 0; i < scene.entries.size(); ++i) {
    const SceneEntry& e = scene.entries[i];
    if (e.fiblets == 0) continue;
    shader::FibletDrawPush push{};
    push.dataset = e.dataset->blockAddress();
    push.camera = frame.camera.address;
    push.list = culled ? culled->list.address + culled->regions[i].list_offset : 0;
    push.fiber_base = e.fiber_base;
    vkCmdPushConstants(cmd, pass.pipeline.layout, pass.pipeline.stages, 0, sizeof(push), &push);
    if (culled) {
      const VkDeviceSize offset = VkDeviceSize(pass.command_first[i]) * sizeof(VkDrawIndirectCommand);
      const uint32_t commands = pass.command_count[i];
      if (commands == 1 || (context.enabledFeatures().multiDrawIndirect && commands <= context.limits().maxDrawIndirectCount)) {
        vkCmdDrawIndirect(cmd, pass.args.buffer, offset, commands, sizeof(VkDrawIndirectCommand));
      } else {
        for (uint32_t k = 0; k < commands; ++k)
          vkCmdDrawIndirect(cmd, pass.args.buffer, offset + k * sizeof(VkDrawIndirectCommand), 1,
                            sizeof(VkDrawIndirectCommand));
      }
    } else {
      gpu::recordPatchDraws(cmd, 0, e.fiblets, pass.patches_per_draw);
    }
  }
  endLineAttachmentsIntoGBuffer(cmd, pass.attachments, frame);
}

}  // namespace fibscope
