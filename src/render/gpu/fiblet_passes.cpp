#include "render/gpu/fiblet_passes.h"

#include <algorithm>

#include <string>

#include "core/error.h"
#include "shared/render_config.h"
#include "shared/render_push.h"

namespace fibscope {

namespace {

// A subgroup scan needs relative shuffles and clusters of `lanes` that tile
// the subgroup.
bool subgroupScanFits(const gpu::DeviceInfo& info, uint32_t lanes) {
  return info.subgroup_shuffle_relative && lanes <= info.subgroup_size && info.subgroup_size % lanes == 0;
}

}  // namespace

uint32_t defaultRasterLanes(const gpu::VulkanContext& context) {
  // CPU devices: one invocation per fiblet, decoded serially
  // (fiblet_raster_serial.comp). lavapipe, the 246 MB tckgen file at 1080p:
  // see docs/BENCHMARKS.md for the serial decode against the 8-lane scan.
  if (context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU) return 1;
  // 8 lanes (8 points each) wherever subgroup shuffles can scan them: the
  // fewest compositions per point. On an H100 (32-wide subgroups, 500 k
  // fibers, 1080p) the raster took 14.8 ms with 8 lanes and four fiblets per
  // subgroup, 16.3 ms with 16 lanes, 18.6 ms with 32 (one fiblet per
  // subgroup, the paper's layout); docs/BENCHMARKS.md.
  if (subgroupScanFits(context.info(), 8)) return 8;
  uint32_t lanes = 8;
  while (lanes < 64 && lanes < context.info().subgroup_size) lanes *= 2;
  return lanes;
}

FibletPasses createFibletPasses(const gpu::VulkanContext& context, uint32_t raster_lanes, RasterScan scan) {
  if (raster_lanes == 0) raster_lanes = defaultRasterLanes(context);
  if (raster_lanes != 1 && raster_lanes != 8 && raster_lanes != 16 && raster_lanes != 32 && raster_lanes != 64)
    throw Error("fiblet raster: lanes per fiblet must be 1, 8, 16, 32 or 64, got " + std::to_string(raster_lanes));
  const bool serial = raster_lanes == 1;
  if (serial && scan != RasterScan::Auto)
    throw Error("fiblet raster: one lane per fiblet decodes serially; it has no scan to choose");
  const bool subgroup_ok = !serial && subgroupScanFits(context.info(), raster_lanes);
  if (scan == RasterScan::Subgroup && !subgroup_ok)
    throw Error("fiblet raster: a subgroup scan of " + std::to_string(raster_lanes) +
                " lanes needs subgroups a multiple of that wide with relative shuffles; " + context.info().name +
                " has " +
                std::to_string(context.info().subgroup_size) + "-wide subgroups" +
                (context.info().subgroup_shuffle_relative ? "" : " without relative shuffles"));
  FibletPasses passes;
  passes.raster_lanes = raster_lanes;
  passes.raster_subgroup_scan = scan == RasterScan::Subgroup || (scan == RasterScan::Auto && subgroup_ok);
  try {
    // CPU devices (lavapipe) pay about a microsecond per workgroup: pack
    // 64 invocations' worth of fiblets into each. GPUs: one subgroup per
    // workgroup with the subgroup scan (fastest on the H100: two or four
    // subgroups per workgroup measured 7-11 % slower), else the paper's one
    // workgroup per fiblet.
    const uint32_t subgroup = context.info().subgroup_size;
    if (serial) {
      passes.raster_fiblets_per_group = std::max<uint32_t>(64, subgroup);
      const uint32_t specialization[] = {passes.raster_fiblets_per_group};
      passes.raster = gpu::createComputePipeline(context, "fiblet_raster_serial.comp",
                                                 sizeof(shader::FibletRasterPush), specialization);
    } else if (context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU)
      passes.raster_fiblets_per_group = std::max<uint32_t>(64, subgroup) / raster_lanes;
    else
      passes.raster_fiblets_per_group = passes.raster_subgroup_scan ? subgroup / raster_lanes : 1;
    if (!serial) {
      const uint32_t specialization[] = {raster_lanes, passes.raster_fiblets_per_group,
                                         raster_lanes * passes.raster_fiblets_per_group};
      passes.raster = gpu::createComputePipeline(
          context, passes.raster_subgroup_scan ? "fiblet_raster_subgroup.comp" : "fiblet_raster.comp",
          sizeof(shader::FibletRasterPush), specialization);
    }
    // Two pipelines, not a branch on the push constant: a CPU device runs
    // both sides of a branch, and the decode is most of the shader.
    const uint32_t cache[] = {1u}, decode[] = {0u};
    passes.resolve =
        gpu::createComputePipeline(context, "fiblet_resolve.comp", sizeof(shader::FibletResolvePush),
                                   gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize}, cache);
    passes.resolve_decode =
        gpu::createComputePipeline(context, "fiblet_resolve.comp", sizeof(shader::FibletResolvePush),
                                   gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize}, decode);
  } catch (...) {
    destroyFibletPasses(context, passes);
    throw;
  }
  return passes;
}

void destroyFibletPasses(const gpu::VulkanContext& context, FibletPasses& passes) {
  gpu::destroyComputePipeline(context, passes.resolve_decode);
  gpu::destroyComputePipeline(context, passes.resolve);
  gpu::destroyComputePipeline(context, passes.raster);
}

uint32_t pixelGroupsX(const GpuFrameTargets& frame) { return shader::pixelGroups(frame.width); }
uint32_t pixelGroupsY(const GpuFrameTargets& frame) { return shader::pixelGroups(frame.height); }

void recordFibletRasterAll(VkCommandBuffer cmd, const gpu::VulkanContext& context, const FibletPasses& passes,
                           const GpuDataset& dataset, const GpuFrameTargets& frame, uint32_t fiblet_base) {
  const uint32_t fiblets = dataset.block().fiblet_count;
  if (fiblets == 0) return;
  shader::FibletRasterPush push{};
  push.dataset = dataset.blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  push.list = 0;
  push.tangents = frame.tangents.address;
  push.fiblet_base = fiblet_base;
  const gpu::DispatchGrid grid =
      gpu::dispatchGrid(context, (uint64_t(fiblets) + passes.raster_fiblets_per_group - 1) / passes.raster_fiblets_per_group);
  gpu::recordDispatch(cmd, passes.raster, push, grid.x, grid.y);
}

void recordFibletRasterList(VkCommandBuffer cmd, const FibletPasses& passes, const GpuDataset& dataset,
                            const GpuFrameTargets& frame, const gpu::Buffer& list, VkDeviceSize list_offset,
                            uint32_t fiblet_base) {
  shader::FibletRasterPush push{};
  push.dataset = dataset.blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  push.list = list.address + list_offset;
  push.tangents = frame.tangents.address;
  push.fiblet_base = fiblet_base;
  gpu::recordDispatchIndirect(cmd, passes.raster, push, list.buffer, list_offset);
}

void recordFibletResolve(VkCommandBuffer cmd, const FibletPasses& passes, VkDeviceAddress scene_table,
                         const GpuFrameTargets& frame) {
  shader::FibletResolvePush push{};
  push.scene = scene_table;
  push.visibility = frame.visibility.address;
  push.gbuffer = frame.gbuffer.address;
  push.tangents = frame.tangents.address;
  push.width = frame.width;
  push.height = frame.height;
  gpu::recordDispatch(cmd, push.tangents != 0 ? passes.resolve : passes.resolve_decode, push, pixelGroupsX(frame),
                      pixelGroupsY(frame));
}

}  // namespace fibscope
