#include "render/gpu_cull_passes.h"

#include <cmath>
#include <cstddef>

#include "gpu/submit.h"
#include "shared/cull_push.h"
#include "shared/fiblet_list.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

constexpr VkDeviceSize kCountOffset = offsetof(shader::FibletListHeader, count);
constexpr uint32_t kLodItemsPerGroup = 64;  // fiblet_lod_raster.comp's local size

// Finalised lists to the indirect dispatch and the rasters' reads.
void computeToIndirect(VkCommandBuffer cmd) {
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
}

// Earlier compute and indirect uses of the lists before transfers
// (statistics copies, counter resets) touch them.
void computeToTransfer(VkCommandBuffer cmd) {
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
}

void transferToCompute(VkCommandBuffer cmd) {
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

// Copies both lists' counts into stats[2 * phase], stats[2 * phase + 1];
// the caller has made the counts visible to transfers.
void copyCounts(VkCommandBuffer cmd, const CullBuffers& buffers, uint32_t phase) {
  VkBufferCopy region{kCountOffset, VkDeviceSize(8) * phase, 4};
  vkCmdCopyBuffer(cmd, buffers.list.buffer, buffers.stats.buffer, 1, &region);
  region.dstOffset += 4;
  vkCmdCopyBuffer(cmd, buffers.lod_list.buffer, buffers.stats.buffer, 1, &region);
}

// Zeroes both lists' headers (count and dispatch size).
void resetLists(VkCommandBuffer cmd, const CullBuffers& buffers) {
  vkCmdFillBuffer(cmd, buffers.list.buffer, 0, sizeof(shader::FibletListHeader), 0);
  vkCmdFillBuffer(cmd, buffers.lod_list.buffer, 0, sizeof(shader::FibletListHeader), 0);
}

void recordCull(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                const GpuDataset& dataset, const GpuFrameTargets& frame, const CullBuffers& buffers, uint32_t mode,
                const CullFrame& cull) {
  shader::FibletCullPush push{};
  push.dataset = dataset.blockAddress();
  push.camera = frame.camera.address;
  push.list = buffers.list.address;
  push.lod_list = buffers.lod_list.address;
  push.visible = buffers.visible.address;
  push.pyramid = buffers.pyramid.address;
  push.mode = mode;
  push.lod_pixels = cull.lod_pixels;
  push.focal_px = cull.focal_px;
  const uint64_t fiblets = dataset.block().fiblet_count;
  const gpu::DispatchGrid grid =
      gpu::dispatchGrid(context, (fiblets + shader::kCullGroupSize - 1) / shader::kCullGroupSize);
  gpu::recordDispatch(cmd, passes.cull, push, grid.x, grid.y);
}

void recordFinalize(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                    const CullBuffers& buffers, const FibletPasses& fiblet_passes) {
  shader::FibletListFinalizePush push{};
  push.max_groups_x = context.limits().maxComputeWorkGroupCount[0];
  push.list = buffers.list.address;
  push.items_per_group = fiblet_passes.raster_fiblets_per_group;  // fiblet_raster.comp (1 on GPUs)
  gpu::recordDispatch(cmd, passes.finalize, push, 1);
  push.list = buffers.lod_list.address;
  push.items_per_group = kLodItemsPerGroup;
  gpu::recordDispatch(cmd, passes.finalize, push, 1);
}

void recordLodRaster(VkCommandBuffer cmd, const CullPasses& passes, const GpuDataset& dataset,
                     const GpuFrameTargets& frame, const CullBuffers& buffers) {
  shader::FibletLodRasterPush push{};
  push.dataset = dataset.blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  push.list = buffers.lod_list.address;
  push.tangents = frame.tangents.address;
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, passes.lod_raster.pipeline);
  vkCmdPushConstants(cmd, passes.lod_raster.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
  vkCmdDispatchIndirect(cmd, buffers.lod_list.buffer, 0);
}

// One cull phase: counters reset -> cull -> finalize, then both rasters.
void recordPhase(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                 const FibletPasses& fiblet_passes, const GpuDataset& dataset, const GpuFrameTargets& frame,
                 const CullBuffers& buffers, uint32_t mode, const CullFrame& cull, gpu::GpuTimer& timer,
                 const char* cull_name, const char* raster_name) {
  gpu::beginPass(cmd, timer, cull_name);
  resetLists(cmd, buffers);
  transferToCompute(cmd);
  recordCull(cmd, context, passes, dataset, frame, buffers, mode, cull);
  gpu::computeToComputeBarrier(cmd);
  recordFinalize(cmd, context, passes, buffers, fiblet_passes);
  gpu::endPass(cmd, timer);
  computeToIndirect(cmd);

  gpu::beginPass(cmd, timer, raster_name);
  recordFibletRasterList(cmd, fiblet_passes, dataset, frame, buffers.list);
  recordLodRaster(cmd, passes, dataset, frame, buffers);
  gpu::endPass(cmd, timer);
}

}  // namespace

CullPasses createCullPasses(const gpu::VulkanContext& context) {
  CullPasses passes;
  try {
    passes.cull = gpu::createComputePipeline(context, "fiblet_cull.comp", sizeof(shader::FibletCullPush));
    passes.finalize =
        gpu::createComputePipeline(context, "fiblet_list_finalize.comp", sizeof(shader::FibletListFinalizePush));
    passes.pyramid = gpu::createComputePipeline(context, "depth_pyramid.comp", sizeof(shader::DepthPyramidPush));
    passes.lod_raster =
        gpu::createComputePipeline(context, "fiblet_lod_raster.comp", sizeof(shader::FibletLodRasterPush));
  } catch (...) {
    destroyCullPasses(context, passes);
    throw;
  }
  return passes;
}

void destroyCullPasses(const gpu::VulkanContext& context, CullPasses& passes) {
  gpu::destroyComputePipeline(context, passes.lod_raster);
  gpu::destroyComputePipeline(context, passes.pyramid);
  gpu::destroyComputePipeline(context, passes.finalize);
  gpu::destroyComputePipeline(context, passes.cull);
}

void prepareCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers, uint32_t fiblets, uint32_t width,
                        uint32_t height) {
  try {
    if (!buffers.stats.buffer)
      buffers.stats = gpu::createBuffer(context, 4 * sizeof(uint32_t), gpu::MemoryUse::Readback);
    if (fiblets > buffers.fiblet_capacity || !buffers.list.buffer) {
      gpu::destroyBuffer(context, buffers.list);
      gpu::destroyBuffer(context, buffers.lod_list);
      gpu::destroyBuffer(context, buffers.visible);
      buffers.fiblet_capacity = 0;
      buffers.history_valid = false;
      const uint64_t capacity = fiblets > 0 ? fiblets : 1;
      const VkDeviceSize list_bytes = sizeof(shader::FibletListHeader) + capacity * sizeof(uint32_t);
      buffers.list =
          gpu::createBuffer(context, list_bytes, gpu::MemoryUse::DeviceLocal, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
      buffers.lod_list =
          gpu::createBuffer(context, list_bytes, gpu::MemoryUse::DeviceLocal, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
      // Whole groups of kCullGroupSize fiblets: a cull workgroup owns its words.
      const uint64_t groups = (capacity + shader::kCullGroupSize - 1) / shader::kCullGroupSize;
      buffers.visible = gpu::createBuffer(context, groups * (shader::kCullGroupSize / 32) * sizeof(uint32_t),
                                          gpu::MemoryUse::DeviceLocal);
      buffers.fiblet_capacity = uint32_t(capacity);
    }
    if (width != buffers.width || height != buffers.height || !buffers.pyramid.buffer) {
      gpu::destroyBuffer(context, buffers.pyramid);
      buffers.width = buffers.height = 0;
      buffers.history_valid = false;
      const uint32_t levels = shader::pyramidLevelCount(width, height);
      const uint64_t texels = shader::pyramidLevelOffset(width, height, levels);
      buffers.pyramid = gpu::createBuffer(context, texels * sizeof(float), gpu::MemoryUse::DeviceLocal);
      buffers.width = width;
      buffers.height = height;
    }
  } catch (...) {
    destroyCullBuffers(context, buffers);
    throw;
  }
}

void destroyCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers) {
  gpu::destroyBuffer(context, buffers.stats);
  gpu::destroyBuffer(context, buffers.pyramid);
  gpu::destroyBuffer(context, buffers.visible);
  gpu::destroyBuffer(context, buffers.lod_list);
  gpu::destroyBuffer(context, buffers.list);
  buffers = CullBuffers{};
}

void recordDepthPyramid(VkCommandBuffer cmd, const CullPasses& passes, const GpuFrameTargets& frame,
                        const CullBuffers& buffers) {
  shader::DepthPyramidPush push{};
  push.visibility = frame.visibility.address;
  push.pyramid = buffers.pyramid.address;
  push.width = frame.width;
  push.height = frame.height;
  const uint32_t levels = shader::pyramidLevelCount(frame.width, frame.height);
  for (uint32_t level = 0; level < levels; ++level) {
    if (level > 0) gpu::computeToComputeBarrier(cmd);
    push.level = level;
    const uint32_t w = shader::pyramidLevelSize(frame.width, level);
    const uint32_t h = shader::pyramidLevelSize(frame.height, level);
    gpu::recordDispatch(cmd, passes.pyramid, push, (w + shader::kPixelGroupSize - 1) / shader::kPixelGroupSize,
                        (h + shader::kPixelGroupSize - 1) / shader::kPixelGroupSize);
  }
}

float cullFocalPixels(const Camera& camera) {
  const Mat4 projection = projectionMatrix(camera);
  return std::fabs(projection[5]) * 0.5f * float(camera.height);
}

void recordCulledRaster(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                        const FibletPasses& fiblet_passes, const GpuDataset& dataset, const GpuFrameTargets& frame,
                        CullBuffers& buffers, const CullFrame& cull, gpu::GpuTimer& timer) {
  const bool two_phase = cull.mode == CullingMode::TwoPhase;
  const bool reset_history = two_phase && (!buffers.history_valid || buffers.history_dataset != dataset.blockAddress());
  // Uses of the lists and bits by earlier work before the resets below.
  computeToTransfer(cmd);
  vkCmdFillBuffer(cmd, buffers.stats.buffer, 0, VK_WHOLE_SIZE, 0);
  if (reset_history) vkCmdFillBuffer(cmd, buffers.visible.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);

  recordPhase(cmd, context, passes, fiblet_passes, dataset, frame, buffers,
              two_phase ? shader::kCullPhase1 : shader::kCullFrustum, cull, timer, two_phase ? "cull 1" : "cull",
              two_phase ? "raster 1" : "raster");
  if (two_phase) {
    // The phase-1 raster's writes to the pyramid; its reads of the lists
    // before their counts are copied and reset.
    gpu::computeToComputeBarrier(cmd);
    computeToTransfer(cmd);
    gpu::beginPass(cmd, timer, "depth pyramid");
    copyCounts(cmd, buffers, 0);
    recordDepthPyramid(cmd, passes, frame, buffers);
    gpu::endPass(cmd, timer);
    // The copies read the counts before recordPhase's reset writes them.
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0);
    gpu::computeToComputeBarrier(cmd);
    recordPhase(cmd, context, passes, fiblet_passes, dataset, frame, buffers, shader::kCullPhase2, cull, timer,
                "cull 2", "raster 2");
  }
  computeToTransfer(cmd);
  copyCounts(cmd, buffers, two_phase ? 1 : 0);
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
  buffers.history_valid = two_phase;
  buffers.history_dataset = dataset.blockAddress();
}

CullStats readCullStats(const gpu::VulkanContext& context, const CullBuffers& buffers) {
  uint32_t counts[4] = {};
  if (buffers.stats.buffer) gpu::downloadFromBuffer(context, buffers.stats, counts, sizeof(counts));
  CullStats stats;
  stats.phase1_full = counts[0];
  stats.phase1_lod = counts[1];
  stats.phase2_full = counts[2];
  stats.phase2_lod = counts[3];
  return stats;
}

}  // namespace fibscope
