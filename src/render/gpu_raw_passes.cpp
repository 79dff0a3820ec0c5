#include "render/gpu_raw_passes.h"

#include "render/gpu_fiblet_passes.h"
#include "shared/raw_tractogram.h"
#include "shared/render_config.h"

namespace fibscope {

RawPasses createRawPasses(const gpu::VulkanContext& context) {
  RawPasses passes;
  try {
    passes.raster = gpu::createComputePipeline(context, "raw_raster.comp", sizeof(shader::RawRasterPush));
    passes.resolve = gpu::createComputePipeline(context, "raw_resolve.comp", sizeof(shader::RawResolvePush));
  } catch (...) {
    destroyRawPasses(context, passes);
    throw;
  }
  return passes;
}

void destroyRawPasses(const gpu::VulkanContext& context, RawPasses& passes) {
  gpu::destroyComputePipeline(context, passes.resolve);
  gpu::destroyComputePipeline(context, passes.raster);
}

void recordRawRaster(VkCommandBuffer cmd, const gpu::VulkanContext& context, const RawPasses& passes,
                     const GpuRawTractogram& tractogram, const GpuFrameTargets& frame) {
  // Candidate segments i -> i + 1 for i < points - 1; the shader skips
  // those that join two streamlines.
  const uint64_t points = tractogram.pointCount();
  if (points < 2) return;
  const uint64_t groups = (points - 1 + shader::kRawRasterGroupSize - 1) / shader::kRawRasterGroupSize;
  shader::RawRasterPush push{};
  push.tractogram = tractogram.blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  const gpu::DispatchGrid grid = gpu::dispatchGrid(context, groups);
  gpu::recordDispatch(cmd, passes.raster, push, grid.x, grid.y);
}

void recordRawResolve(VkCommandBuffer cmd, const RawPasses& passes, const GpuRawTractogram& tractogram,
                      const GpuFrameTargets& frame) {
  shader::RawResolvePush push{};
  push.tractogram = tractogram.blockAddress();
  push.visibility = frame.visibility.address;
  push.gbuffer = frame.gbuffer.address;
  push.width = frame.width;
  push.height = frame.height;
  gpu::recordDispatch(cmd, passes.resolve, push, pixelGroupsX(frame), pixelGroupsY(frame));
}

}  // namespace fibscope
