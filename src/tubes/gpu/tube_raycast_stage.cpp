// Surfaces: the spline tubes ray-cast by compute (shared/tubes.h: the
// binning pass and the per-pixel pass), for compute-only devices and
// lavapipe, whose graphics pipeline is slow.
#include <algorithm>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "shared/tubes.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {
namespace {

constexpr uint32_t kMaxGroupsX = 65535;  // Vulkan's guaranteed maxComputeWorkGroupCount[0]

class TubeRaycastStage final : public FrameStage {
 public:
  explicit TubeRaycastStage(const GpuTubes* tubes) : tubes_(tubes) {}
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyBuffer(context, overflow_readback_);
    gpu::destroyBuffer(context, tile_lists_);
    gpu::destroyBuffer(context, tile_counts_);
    gpu::destroyComputePipeline(context, raycast_);
    gpu::destroyComputePipeline(context, bin_);
  }
  uint32_t maxPasses() const override { return 2; }
  bool runs(const FrameContext&) const override { return tubes_ && tubes_->segment_count > 0; }
  bool drawsSurfaces() const override { return true; }
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override {
    gpu::destroyBuffer(context, tile_lists_);
    gpu::destroyBuffer(context, tile_counts_);
  }

  void record(FrameContext& frame) override {
    if (bin_.pipeline == VK_NULL_HANDLE) {
      bin_ = gpu::createComputePipeline(frame.context, "tube_bin.comp", sizeof(shader::TubeBinPush),
                                        gpu::WorkgroupSize{shader::kTubeBinGroupSize});
      raycast_ = gpu::createComputePipeline(frame.context, "tube_raycast.comp", sizeof(shader::TubeRaycastPush),
                                            gpu::WorkgroupSize{shader::kTubeTileSize, shader::kTubeTileSize});
    }
    const uint32_t width = frame.targets.width, height = frame.targets.height;
    const uint32_t tiles_x = (width + shader::kTubeTileSize - 1) / shader::kTubeTileSize;
    const uint32_t tiles_y = (height + shader::kTubeTileSize - 1) / shader::kTubeTileSize;
    const VkDeviceSize tiles = VkDeviceSize(tiles_x) * tiles_y;
    if (!tile_counts_.buffer) {
      // One more word: the count of overflowing tiles.
      tile_counts_ = gpu::createBuffer(frame.context, (tiles + 1) * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
      tile_lists_ = gpu::createBuffer(frame.context, tiles * shader::kTubeTileCapacity * sizeof(uint32_t),
                                      gpu::MemoryUse::DeviceLocal);
    }
    // The previous frame's reads of the counts before they are cleared.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdFillBuffer(frame.cmd, tile_counts_.buffer, 0, VK_WHOLE_SIZE, 0);
    gpu::recordBarrier(frame.cmd, gpu::kTransferToCompute);

    const uint32_t items = tubes_->subSegmentCount();
    {
      gpu::PassScope pass(frame.cmd, frame.timer, "tube bin", gpu::kComputeToCompute);
      shader::TubeBinPush push{};
      push.camera = frame.targets.camera.address;
      push.nodes = tubes_->nodes.address;
      push.segments = tubes_->segments.address;
      push.tile_counts = tile_counts_.address;
      push.tile_lists = tile_lists_.address;
      push.sub_segments = items;
      push.tiles_x = tiles_x;
      push.tiles_y = tiles_y;
      const uint32_t groups = (items + shader::kTubeBinGroupSize - 1) / shader::kTubeBinGroupSize;
      const uint32_t gx = std::min(groups, kMaxGroupsX), gy = (groups + gx - 1) / gx;
      gpu::recordDispatch(frame.cmd, bin_, push, gx, gy);
    }
    {
      gpu::PassScope pass(frame.cmd, frame.timer, "tube raycast", gpu::kComputeToCompute);
      shader::TubeRaycastPush push{};
      push.camera = frame.targets.camera.address;
      push.nodes = tubes_->nodes.address;
      push.segments = tubes_->segments.address;
      push.tile_counts = tile_counts_.address;
      push.tile_lists = tile_lists_.address;
      push.surface = frame.targets.surface.address;
      push.sub_segments = items;
      push.tiles_x = tiles_x;
      push.width = width;
      push.height = height;
      gpu::recordDispatch(frame.cmd, raycast_, push, tiles_x, tiles_y);
    }
    // The overflow count to the host, read in collect().
    if (!overflow_readback_.buffer)
      overflow_readback_ = gpu::createBuffer(frame.context, sizeof(uint32_t), gpu::MemoryUse::Readback);
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite,
                                   VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT});
    const VkBufferCopy region{tiles * sizeof(uint32_t), 0, sizeof(uint32_t)};
    vkCmdCopyBuffer(frame.cmd, tile_counts_.buffer, overflow_readback_.buffer, 1, &region);
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                   VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT});
    recorded_ = true;
  }

  void collect(const gpu::VulkanContext& context, FrameStats& stats) override {
    if (!recorded_) return;
    recorded_ = false;
    uint32_t overflowed = 0;
    gpu::downloadFromBuffer(context, overflow_readback_, &overflowed, sizeof(overflowed));
    stats.tube_tiles_overflowed = overflowed;
    stats.tube_method_bytes = tile_counts_.size + tile_lists_.size;
  }

 private:
  const GpuTubes* tubes_;
  gpu::ComputePipeline bin_, raycast_;  // made at the first frame with tubes
  gpu::Buffer tile_counts_;             // uint per tile
  gpu::Buffer tile_lists_;              // kTubeTileCapacity sub-segment indices per tile
  gpu::Buffer overflow_readback_;       // the frame's count of overflowing tiles
  bool recorded_ = false;               // a frame was recorded since the last collect
};

}  // namespace

FrameStageFactory tubeRaycastStage(const GpuTubes* tubes) {
  return [tubes](const gpu::VulkanContext&) { return std::make_unique<TubeRaycastStage>(tubes); };
}

}  // namespace fibscope
