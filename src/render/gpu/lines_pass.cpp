#include "render/gpu/lines_pass.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "shared/raw_tractogram.h"
#include "shared/render_config.h"

namespace fibscope {

LinesPass createLinesPass(const gpu::VulkanContext& context) {
  if (!context.info().queue_has_graphics)
    throw Error("render: the lines pipeline needs a graphics queue, " + context.info().name +
                " has none (use the compute or raw-compute pipeline)");
  if (!context.enabledFeatures().shaderClipDistance)
    throw Error("render: the lines pipeline clips with gl_ClipDistance, which " + context.info().name +
                " lacks (use the compute or raw-compute pipeline)");
  gpu::GraphicsPipelineDesc desc;
  desc.vertex_shader = "lines.vert";
  desc.fragment_shader = "lines.frag";
  desc.topology = VK_PRIMITIVE_TOPOLOGY_LINE_STRIP;
  desc.color_format = kLineColorFormat;
  desc.depth_format = kLineDepthFormat;
  desc.push_constant_bytes = sizeof(shader::LinesPush);
  desc.dynamic_line_width = true;
  LinesPass pass;
  pass.pipeline = gpu::createGraphicsPipeline(context, desc);
  return pass;
}

void destroyLinesPass(const gpu::VulkanContext& context, LinesPass& pass) {
  releaseLinesAttachments(context, pass);
  gpu::destroyGraphicsPipeline(context, pass.pipeline);
}

void releaseLinesAttachments(const gpu::VulkanContext& context, LinesPass& pass) {
  releaseLineAttachments(context, pass.attachments);
}

void ensureLinesAttachments(const gpu::VulkanContext& context, LinesPass& pass, uint32_t width, uint32_t height) {
  ensureLineAttachments(context, pass.attachments, width, height);
}

float linesDrawnWidth(const gpu::VulkanContext& context, float requested_px) {
  if (!context.enabledFeatures().wideLines) return 1.0f;
  const VkPhysicalDeviceLimits& limits = context.limits();
  float width = std::clamp(requested_px, limits.lineWidthRange[0], limits.lineWidthRange[1]);
  const float step = limits.lineWidthGranularity;
  if (step > 0.0f) width = limits.lineWidthRange[0] + std::round((width - limits.lineWidthRange[0]) / step) * step;
  return std::clamp(width, limits.lineWidthRange[0], limits.lineWidthRange[1]);
}

void recordLines(VkCommandBuffer cmd, const gpu::VulkanContext& context, LinesPass& pass,
                 const GpuRawTractogram& tractogram, const GpuFrameTargets& frame, float line_width_px,
                 VkDeviceAddress kept_bits) {
  beginLineAttachments(cmd, pass.attachments);
  const uint32_t streamlines = tractogram.streamlineCount();
  if (streamlines > 0) {
    shader::LinesPush push{};
    push.tractogram = tractogram.blockAddress();
    push.camera = frame.camera.address;
    push.kept = kept_bits;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pass.pipeline.pipeline);
    vkCmdSetLineWidth(cmd, linesDrawnWidth(context, line_width_px));
    // Chunk by chunk, the chunk in the push constants (the vertex shader
    // pulls from its buffer); streamlines in order, so primitive order, and
    // with it the depth test's ties, is that of one draw over all of them.
    const uint32_t per_call = std::max<uint32_t>(context.limits().maxDrawIndirectCount, 1);
    for (uint32_t c = 0; c < tractogram.chunkCount(); ++c) {
      const shader::RawChunk& chunk = tractogram.chunk(c).entry;
      if (chunk.point_count < 2) continue;
      push.chunk = c;
      vkCmdPushConstants(cmd, pass.pipeline.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                         sizeof(push), &push);
      const uint32_t begin = chunk.first_streamline, end = chunk.first_streamline + chunk.streamline_count;
      if (tractogram.hostCounts().empty()) {
        // The chunk's streamlines in as few indirect draws as
        // maxDrawIndirectCount allows (one on every device we know of).
        for (uint32_t first = begin; first < end; first += std::min(per_call, end - first))
          vkCmdDrawIndirect(cmd, tractogram.draws().buffer, VkDeviceSize(first) * sizeof(VkDrawIndirectCommand),
                            std::min(per_call, end - first), sizeof(VkDrawIndirectCommand));
      } else {
        const std::vector<uint32_t>& counts = tractogram.hostCounts();
        for (uint32_t s = begin; s < end; ++s)
          if (counts[s] >= 2) vkCmdDraw(cmd, counts[s], 1, 0, s);
      }
    }
  }
  endLineAttachmentsIntoGBuffer(cmd, pass.attachments, frame);
}

}  // namespace fibscope
