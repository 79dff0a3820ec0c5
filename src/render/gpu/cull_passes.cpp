#include "render/gpu/cull_passes.h"

#include <cmath>
#include <algorithm>
#include <cstddef>
#include <string>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "shared/coverage_push.h"
#include "shared/cull_push.h"
#include "shared/fiblet_list.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

void checkRegionsMatch(const SceneLayout& scene, const CullBuffers& buffers) {
  if (scene.entries.size() != buffers.regions.size())
    throw Error("cull: the buffers were prepared for " + std::to_string(buffers.regions.size()) +
                " datasets, the scene has " + std::to_string(scene.entries.size()));
}

constexpr VkDeviceSize kCountOffset = offsetof(shader::FibletListHeader, count);
// Earlier compute and indirect uses of the lists before transfers
// (statistics copies, counter resets) touch them.
void computeToTransfer(VkCommandBuffer cmd) {
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
}

// Copies each region's two list counts into its stats slots 2 * phase and
// 2 * phase + 1; the caller has made the counts visible to transfers.
void copyCounts(VkCommandBuffer cmd, const CullBuffers& buffers, uint32_t phase) {
  for (size_t i = 0; i < buffers.regions.size(); ++i) {
    const CullRegion& r = buffers.regions[i];
    VkBufferCopy region{r.list_offset + kCountOffset, VkDeviceSize(16) * i + VkDeviceSize(8) * phase, 4};
    vkCmdCopyBuffer(cmd, buffers.list.buffer, buffers.stats.buffer, 1, &region);
    region.dstOffset += 4;
    vkCmdCopyBuffer(cmd, buffers.lod_list.buffer, buffers.stats.buffer, 1, &region);
  }
}

// Zeroes every region's list headers (count and dispatch size).
void resetLists(VkCommandBuffer cmd, const CullBuffers& buffers) {
  for (const CullRegion& r : buffers.regions) {
    vkCmdFillBuffer(cmd, buffers.list.buffer, r.list_offset, sizeof(shader::FibletListHeader), 0);
    vkCmdFillBuffer(cmd, buffers.lod_list.buffer, r.list_offset, sizeof(shader::FibletListHeader), 0);
  }
}

void recordCull(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                const SceneEntry& entry, const CullRegion& region, const GpuFrameTargets& frame,
                const CullBuffers& buffers, uint32_t mode, const CullFrame& cull) {
  const GpuDataset& dataset = *entry.dataset;
  const uint64_t fiblets = dataset.block().fiblet_count;
  if (fiblets == 0) return;
  shader::FibletCullPush push{};
  push.dataset = dataset.blockAddress();
  push.camera = frame.camera.address;
  push.list = buffers.list.address + region.list_offset;
  push.lod_list = buffers.lod_list.address + region.list_offset;
  push.visible = buffers.visible.address + region.visible_offset;
  push.pyramid = buffers.pyramid.address;
  push.kept = cull.kept_bits;
  push.fiber_base = entry.fiber_base;
  push.mode = mode;
  push.lod_pixels = cull.lod_pixels;
  push.focal_px = cull.focal_px;
  const gpu::DispatchGrid grid =
      gpu::dispatchGrid(context, (fiblets + shader::kCullGroupSize - 1) / shader::kCullGroupSize);
  gpu::recordDispatch(cmd, passes.cull, push, grid.x, grid.y);
}

void recordFinalize(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                    const CullBuffers& buffers, const FibletPasses& fiblet_passes) {
  shader::FibletListFinalizePush push{};
  push.max_groups_x = context.limits().maxComputeWorkGroupCount[0];
  for (const CullRegion& r : buffers.regions) {
    push.list = buffers.list.address + r.list_offset;
    push.items_per_group = fiblet_passes.raster_fiblets_per_group;  // fiblet_raster.comp (1 on GPUs)
    gpu::recordDispatch(cmd, passes.finalize, push, 1);
    push.list = buffers.lod_list.address + r.list_offset;
    push.items_per_group = shader::kLodRasterGroupSize;
    gpu::recordDispatch(cmd, passes.finalize, push, 1);
  }
}

void recordLodRaster(VkCommandBuffer cmd, const CullPasses& passes, const SceneEntry& entry, const CullRegion& region,
                     const GpuFrameTargets& frame, const CullBuffers& buffers) {
  shader::FibletLodRasterPush push{};
  push.dataset = entry.dataset->blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  push.list = buffers.lod_list.address + region.list_offset;
  push.tangents = frame.tangents.address;
  push.fiblet_base = entry.fiblet_base;
  gpu::recordDispatchIndirect(cmd, passes.lod_raster, push, buffers.lod_list.buffer, region.list_offset);
}

// One cull phase over every dataset: counters reset -> culls -> finalizes
// (pass `cull_name`, its lists then ready for indirect dispatch), then
// every dataset's two rasters (pass `raster_name`; atomicMin into one
// visibility buffer: no barrier between datasets), their writes before
// later compute passes.
void recordPhase(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                 const FibletPasses& fiblet_passes, const SceneLayout& scene, const GpuFrameTargets& frame,
                 const CullBuffers& buffers, uint32_t mode, const CullFrame& cull, gpu::GpuTimer* timer,
                 const char* cull_name, const char* raster_name) {
  {
    gpu::PassScope pass(cmd, timer, cull_name, gpu::kComputeToIndirect);
    resetLists(cmd, buffers);
    gpu::recordBarrier(cmd, gpu::kTransferToCompute);
    for (size_t i = 0; i < scene.entries.size(); ++i)
      recordCull(cmd, context, passes, scene.entries[i], buffers.regions[i], frame, buffers, mode, cull);
    gpu::computeToComputeBarrier(cmd);
    recordFinalize(cmd, context, passes, buffers, fiblet_passes);
  }
  gpu::PassScope pass(cmd, timer, raster_name, gpu::kComputeToCompute);
  for (size_t i = 0; i < scene.entries.size(); ++i) {
    const CullRegion& region = buffers.regions[i];
    recordFibletRasterList(cmd, fiblet_passes, *scene.entries[i].dataset, frame, buffers.list, region.list_offset,
                           scene.entries[i].fiblet_base);
    recordLodRaster(cmd, passes, scene.entries[i], region, frame, buffers);
  }
}

}  // namespace

gpu::ComputePipeline createListFinalizePipeline(const gpu::VulkanContext& context) {
  return gpu::createComputePipeline(context, "fiblet_list_finalize.comp", sizeof(shader::FibletListFinalizePush));
}

CullPasses createCullPasses(const gpu::VulkanContext& context) {
  CullPasses passes;
  try {
    passes.cull = gpu::createComputePipeline(context, "fiblet_cull.comp", sizeof(shader::FibletCullPush),
                                             gpu::WorkgroupSize{shader::kCullGroupSize});
    passes.finalize = createListFinalizePipeline(context);
    passes.pyramid = gpu::createComputePipeline(context, "depth_pyramid.comp", sizeof(shader::DepthPyramidPush),
                                                gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
    passes.lod_raster =
        gpu::createComputePipeline(context, "fiblet_lod_raster.comp", sizeof(shader::FibletLodRasterPush),
                                   gpu::WorkgroupSize{shader::kLodRasterGroupSize});
    passes.coverage = createCoveragePipeline(context);
  } catch (...) {
    destroyCullPasses(context, passes);
    throw;
  }
  return passes;
}

void destroyCullPasses(const gpu::VulkanContext& context, CullPasses& passes) {
  gpu::destroyComputePipeline(context, passes.coverage);
  gpu::destroyComputePipeline(context, passes.lod_raster);
  gpu::destroyComputePipeline(context, passes.pyramid);
  gpu::destroyComputePipeline(context, passes.finalize);
  gpu::destroyComputePipeline(context, passes.cull);
}

void prepareCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers,
                        std::span<const uint32_t> dataset_fiblets, uint32_t width, uint32_t height,
                        bool coverage) {
  if (dataset_fiblets.size() > shader::kMaxSceneDatasets)
    throw Error("cull: at most " + std::to_string(shader::kMaxSceneDatasets) + " datasets per frame, got " +
                std::to_string(dataset_fiblets.size()));
  // The regions: lists 16-byte aligned (a header each, then the indices),
  // bits in whole cull workgroups so a workgroup owns its words.
  std::vector<CullRegion> regions;
  VkDeviceSize list_bytes = 0, visible_bytes = 0;
  for (const uint32_t fiblets : dataset_fiblets) {
    CullRegion r;
    r.fiblets = fiblets;
    r.list_offset = list_bytes;
    r.visible_offset = visible_bytes;
    list_bytes += (sizeof(shader::FibletListHeader) + uint64_t(fiblets) * sizeof(uint32_t) + 15) / 16 * 16;
    const uint64_t groups = (uint64_t(fiblets) + shader::kCullGroupSize - 1) / shader::kCullGroupSize;
    visible_bytes += groups * (shader::kCullGroupSize / 32) * sizeof(uint32_t);
    regions.push_back(r);
  }
  list_bytes = std::max<VkDeviceSize>(list_bytes, sizeof(shader::FibletListHeader));
  visible_bytes = std::max<VkDeviceSize>(visible_bytes, 4);
  // (Another layout moves the regions; recordCulledRaster's sameScene
  // check then resets the history.)
  buffers.regions = std::move(regions);
  try {
    if (!buffers.stats.buffer)
      buffers.stats = gpu::createBuffer(context, shader::kMaxSceneDatasets * 4 * sizeof(uint32_t),
                                        gpu::MemoryUse::Readback);
    if (list_bytes > buffers.list_capacity || visible_bytes > buffers.visible_capacity || !buffers.list.buffer) {
      gpu::destroyBuffer(context, buffers.list);
      gpu::destroyBuffer(context, buffers.lod_list);
      gpu::destroyBuffer(context, buffers.visible);
      buffers.list_capacity = buffers.visible_capacity = 0;
      buffers.history_valid = false;
      buffers.list =
          gpu::createBuffer(context, list_bytes, gpu::MemoryUse::DeviceLocal, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
      buffers.lod_list =
          gpu::createBuffer(context, list_bytes, gpu::MemoryUse::DeviceLocal, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
      buffers.visible = gpu::createBuffer(context, visible_bytes, gpu::MemoryUse::DeviceLocal);
      buffers.list_capacity = list_bytes;
      buffers.visible_capacity = visible_bytes;
    }
    if (width != buffers.width || height != buffers.height || !buffers.pyramid.buffer) {
      gpu::destroyBuffer(context, buffers.pyramid);
      buffers.width = buffers.height = 0;
      buffers.history_valid = false;
      buffers.coverage.valid = false;
      const uint32_t levels = shader::pyramidLevelCount(width, height);
      const uint64_t texels = shader::pyramidLevelOffset(width, height, levels);
      buffers.pyramid = gpu::createBuffer(context, texels * sizeof(float), gpu::MemoryUse::DeviceLocal);
      buffers.width = width;
      buffers.height = height;
    }
    if (coverage) prepareCoverageHistory(context, buffers.coverage, width, height);
  } catch (...) {
    destroyCullBuffers(context, buffers);
    throw;
  }
}

void prepareCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers, uint32_t fiblets, uint32_t width,
                        uint32_t height, bool coverage) {
  const uint32_t one[] = {fiblets};
  prepareCullBuffers(context, buffers, one, width, height, coverage);
}

void destroyCullBuffers(const gpu::VulkanContext& context, CullBuffers& buffers) {
  destroyCoverageHistory(context, buffers.coverage);
  gpu::destroyBuffer(context, buffers.stats);
  gpu::destroyBuffer(context, buffers.pyramid);
  gpu::destroyBuffer(context, buffers.visible);
  gpu::destroyBuffer(context, buffers.lod_list);
  gpu::destroyBuffer(context, buffers.list);
  buffers = CullBuffers{};
}

void recordDepthPyramid(VkCommandBuffer cmd, const CullPasses& passes, const GpuFrameTargets& frame,
                        const CullBuffers& buffers, uint32_t first_level, bool from_gbuffer) {
  shader::DepthPyramidPush push{};
  push.visibility = frame.visibility.address;
  push.gbuffer = from_gbuffer ? frame.gbuffer.address : 0;
  push.pyramid = buffers.pyramid.address;
  push.width = frame.width;
  push.height = frame.height;
  const uint32_t levels = shader::pyramidLevelCount(frame.width, frame.height);
  for (uint32_t level = first_level; level < levels; ++level) {
    if (level > first_level) gpu::computeToComputeBarrier(cmd);
    push.level = level;
    const uint32_t w = shader::pyramidLevelSize(frame.width, level);
    const uint32_t h = shader::pyramidLevelSize(frame.height, level);
    gpu::recordDispatch(cmd, passes.pyramid, push, shader::pixelGroups(w), shader::pixelGroups(h));
  }
}

float cullFocalPixels(const Camera& camera) {
  const Mat4 projection = projectionMatrix(camera);
  return std::fabs(projection[5]) * 0.5f * float(camera.height);
}

void recordCulledRaster(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                        const FibletPasses& fiblet_passes, const SceneLayout& scene, const GpuFrameTargets& frame,
                        CullBuffers& buffers, const CullFrame& cull, gpu::GpuTimer* timer) {
  checkRegionsMatch(scene, buffers);
  const bool two_phase = cull.mode == CullingMode::TwoPhase;
  const bool coverage = cull.mode == CullingMode::Coverage;
  const bool reset_history = two_phase && (!buffers.history_valid || !sameScene(buffers.history_scene, scene));
  if (coverage && !buffers.coverage.previous_keys.buffer)
    throw Error("cull: coverage culling needs buffers prepared for it");
  // The last Coverage frame can be re-projected: same scene and size.
  const bool reproject = coverage && buffers.coverage.valid && sameScene(buffers.coverage.scene, scene) &&
                         buffers.coverage.camera.width == frame.width &&
                         buffers.coverage.camera.height == frame.height;
  // Uses of the lists and bits by earlier work before the resets below.
  computeToTransfer(cmd);
  vkCmdFillBuffer(cmd, buffers.stats.buffer, 0, VK_WHOLE_SIZE, 0);
  if (reset_history) vkCmdFillBuffer(cmd, buffers.visible.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);

  if (reproject) {
    // The coverage buffer is the pyramid's level 0 (float bits, far = 1.0
    // where no splat lands), then its max-mip levels.
    gpu::PassScope pass(cmd, timer, "coverage", gpu::kComputeToCompute);
    vkCmdFillBuffer(cmd, buffers.pyramid.buffer, 0, frame.pixels() * sizeof(float), shader::kCoverageFarBits);
    gpu::recordBarrier(cmd, gpu::kTransferToCompute);
    recordCoverageReproject(cmd, passes.coverage, buffers.coverage, cull.camera, frame, buffers.pyramid.address,
                            cull.coverage_splat_px);
    gpu::computeToComputeBarrier(cmd);
    recordDepthPyramid(cmd, passes, frame, buffers, 1);
  }

  const uint32_t first_mode = two_phase                           ? shader::kCullPhase1
                              : reproject                         ? shader::kCullCoverage
                              : cull.mode == CullingMode::None    ? shader::kCullKeptOnly
                                                                  : shader::kCullFrustum;
  recordPhase(cmd, context, passes, fiblet_passes, scene, frame, buffers, first_mode, cull, timer,
              two_phase ? "cull 1" : "cull", two_phase ? "raster 1" : "raster");
  if (two_phase) {
    // (The phase-1 raster's writes before the pyramid: its pass's barrier.)
    // Its reads of the lists before their counts are copied and reset.
    computeToTransfer(cmd);
    {
      gpu::PassScope pass(cmd, timer, "depth pyramid", gpu::kComputeToCompute);
      copyCounts(cmd, buffers, 0);
      recordDepthPyramid(cmd, passes, frame, buffers);
    }
    // The copies read the counts before recordPhase's reset writes them.
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0);
    recordPhase(cmd, context, passes, fiblet_passes, scene, frame, buffers, shader::kCullPhase2, cull, timer,
                "cull 2", "raster 2");
  }
  computeToTransfer(cmd);
  copyCounts(cmd, buffers, two_phase ? 1 : 0);
  if (coverage) {
    // The raster's keys (visible to transfers: the barrier above) for the
    // next frame's re-projection; its compute reads after this copy.
    const VkBufferCopy region{0, 0, buffers.coverage.previous_keys.size};
    vkCmdCopyBuffer(cmd, frame.visibility.buffer, buffers.coverage.previous_keys.buffer, 1, &region);
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_TRANSFER_READ_BIT,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                       gpu::kStorageReadWrite | VK_ACCESS_2_TRANSFER_WRITE_BIT);
    buffers.coverage.camera = cull.camera;
    buffers.coverage.scene = scene;
  }
  buffers.coverage.valid = coverage;
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
  buffers.history_valid = two_phase;
  buffers.history_scene = scene;
}

void recordCullLists(VkCommandBuffer cmd, const gpu::VulkanContext& context, const CullPasses& passes,
                     const SceneLayout& scene, const GpuFrameTargets& frame, CullBuffers& buffers,
                     const CullFrame& cull, uint32_t phase) {
  checkRegionsMatch(scene, buffers);
  const bool two_phase = cull.mode == CullingMode::TwoPhase;
  if (cull.lod_pixels != 0.0f || two_phase != (phase != 0))
    throw Error("cull: the list-only cull is without LoD, and in phases 1 and 2 for TwoPhase only");
  recordCullCountersReset(cmd, buffers, scene, phase, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
  const uint32_t mode = phase == 1                          ? shader::kCullPhase1
                        : phase == 2                        ? shader::kCullPhase2
                        : cull.mode == CullingMode::Frustum ? shader::kCullFrustum
                                                            : shader::kCullKeptOnly;
  for (size_t i = 0; i < scene.entries.size(); ++i)
    recordCull(cmd, context, passes, scene.entries[i], buffers.regions[i], frame, buffers, mode, cull);
  gpu::computeToComputeBarrier(cmd);
  markCullHistory(buffers, scene, phase);
}

void recordCullCountersReset(VkCommandBuffer cmd, CullBuffers& buffers, const SceneLayout& scene, uint32_t phase,
                             VkPipelineStageFlags2 consumers) {
  checkRegionsMatch(scene, buffers);
  computeToTransfer(cmd);
  if (phase == 2) {
    // The phase-1 count copies before the resets below (write-after-read).
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_2_TRANSFER_BIT, 0);
  } else {
    vkCmdFillBuffer(cmd, buffers.stats.buffer, 0, VK_WHOLE_SIZE, 0);
  }
  if (phase == 1 && (!buffers.history_valid || !sameScene(buffers.history_scene, scene)))
    vkCmdFillBuffer(cmd, buffers.visible.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
  resetLists(cmd, buffers);
  // (All transfer stages: validation files the fills under COPY, the spec
  // under CLEAR; kTransferToCompute's barrier for compute consumers.)
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, consumers,
                     gpu::kStorageReadWrite);
}

void markCullHistory(CullBuffers& buffers, const SceneLayout& scene, uint32_t phase) {
  buffers.history_valid = phase == 2;
  if (phase == 2) buffers.history_scene = scene;
}

void recordCullListStats(VkCommandBuffer cmd, const CullBuffers& buffers, uint32_t phase) {
  copyCounts(cmd, buffers, phase == 2 ? 1 : 0);
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

void collectCullStats(const gpu::VulkanContext& context, const CullBuffers& buffers, FrameStats& stats) {
  const CullStats cull = readCullStats(context, buffers);
  stats.fiblets_drawn = cull.full();
  stats.fiblets_lod = cull.lod();
}

CullStats readCullStats(const gpu::VulkanContext& context, const CullBuffers& buffers) {
  CullStats stats;
  if (!buffers.stats.buffer || buffers.regions.empty()) return stats;
  std::vector<uint32_t> counts(4 * buffers.regions.size());
  gpu::downloadFromBuffer(context, buffers.stats, counts.data(), counts.size() * sizeof(uint32_t));
  for (size_t i = 0; i < buffers.regions.size(); ++i) {
    stats.phase1_full += counts[4 * i];
    stats.phase1_lod += counts[4 * i + 1];
    stats.phase2_full += counts[4 * i + 2];
    stats.phase2_lod += counts[4 * i + 3];
  }
  return stats;
}

void checkFibletLinePipeline(RenderPipeline kind, const RenderSettings& settings, bool has_fiblets) {
  if (!has_fiblets) throw Error("render: the " + std::string(renderPipelineName(kind)) + " pipeline needs fiblets");
  if (settings.culling == CullingMode::Coverage)
    throw Error("render: coverage culling is the compute pipeline's; the " + std::string(renderPipelineName(kind)) +
                " pipeline takes none, frustum or two-phase");
}

}  // namespace fibscope
