#include "render/gpu/raw_passes.h"

#include "render/gpu/fiblet_passes.h"
#include "shared/raw_tractogram.h"
#include "shared/render_config.h"

namespace fibscope {

RawPasses createRawPasses(const gpu::VulkanContext& context) {
  RawPasses passes;
  try {
    passes.raster = gpu::createComputePipeline(context, "raw_raster.comp", sizeof(shader::RawRasterPush),
                                                 gpu::WorkgroupSize{shader::kRawRasterGroupSize});
    passes.resolve = gpu::createComputePipeline(context, "raw_resolve.comp", sizeof(shader::RawResolvePush),
                                                  gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
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
                     const GpuRawTractogram& tractogram, const GpuFrameTargets& frame, VkDeviceAddress kept_points) {
  // One dispatch per chunk over its candidate segments j -> j + 1, j <
  // points - 1; the shader skips those that join two streamlines. The
  // dispatches only meet in atomic minima on the visibility buffer, so they
  // need no barriers between them.
  shader::RawRasterPush push{};
  push.tractogram = tractogram.blockAddress();
  push.camera = frame.camera.address;
  push.visibility = frame.visibility.address;
  push.kept_points = kept_points;
  for (uint32_t c = 0; c < tractogram.chunkCount(); ++c) {
    const uint64_t points = tractogram.chunk(c).entry.point_count;
    if (points < 2) continue;
    const uint64_t groups = (points - 1 + shader::kRawRasterGroupSize - 1) / shader::kRawRasterGroupSize;
    push.chunk = c;
    const gpu::DispatchGrid grid = gpu::dispatchGrid(context, groups);
    gpu::recordDispatch(cmd, passes.raster, push, grid.x, grid.y);
  }
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
