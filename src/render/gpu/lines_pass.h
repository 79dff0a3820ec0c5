// The lines baseline (DESIGN.md section 6; the "basic OpenGL" column of the
// paper's table 3): the uncompressed float vertices drawn as line strips
// through the graphics pipeline, no culling, into the line attachments
// (line_attachments.h: the G-buffer texel's four words and a D32 depth),
// then copied into GpuFrameTargets::gbuffer, so shading reads the same
// layout whatever pipeline drew the frame.
//
// Line rasterisation is the device's (Bresenham-like "diamond exit" at
// width 1, parallelograms or rectangles for wide lines), not the CPU
// reference's capsule rule, so coverage differs from the compute pipelines
// by up to about a pixel; tests measure by how much.
//
// One vkCmdDrawIndirect per chunk of points covers its streamlines
// (firstInstance = the streamline; the chunk, whose buffer the vertex
// shader pulls from, in the push constants) where the device has
// multiDrawIndirect and drawIndirectFirstInstance; otherwise one vkCmdDraw
// per streamline from the host's counts. Widths above 1 need wideLines; without it, lines are 1
// px wide.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/graphics_pipeline.h"
#include "gpu/image.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/frame_targets.h"
#include "render/gpu/line_attachments.h"
#include "render/gpu/raw_tractogram.h"

namespace fibscope {

struct LinesPass {
  gpu::GraphicsPipeline pipeline;  // lines.vert + lines.frag
  LineAttachments attachments;     // none until the first frame
};

// The pipeline (attachments come with ensureLinesAttachments). Throws Error
// when the device's queue has no graphics (compute-only devices) or the
// pipeline cannot be created.
LinesPass createLinesPass(const gpu::VulkanContext& context);
void destroyLinesPass(const gpu::VulkanContext& context, LinesPass& pass);

// Attachments of width x height; replaces others of another size (waits
// for the device to be idle first). Throws Error when memory runs out.
void ensureLinesAttachments(const gpu::VulkanContext& context, LinesPass& pass, uint32_t width, uint32_t height);
// Frees the attachments (the device must not be using them).
void releaseLinesAttachments(const gpu::VulkanContext& context, LinesPass& pass);

// The width the device draws for a requested width: clamped to its line
// width range and rounded to its granularity with wideLines, else 1.
float linesDrawnWidth(const gpu::VulkanContext& context, float requested_px);

// Clears the attachments, draws every streamline (the fiber filter's kept
// ones: `kept_bits`, GpuScene::kept_bits, 0 for all) and copies the colour
// attachment into frame.gbuffer (written at the TRANSFER stage when this
// returns). The attachments must be the frame's size, the camera block in
// frame.camera visible to vertex-shader reads.
void recordLines(VkCommandBuffer cmd, const gpu::VulkanContext& context, LinesPass& pass,
                 const GpuRawTractogram& tractogram, const GpuFrameTargets& frame, float line_width_px,
                 VkDeviceAddress kept_bits = 0);

}  // namespace fibscope
