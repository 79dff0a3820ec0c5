// Surfaces: the spline tubes ray-cast by compute (shared/tubes.h: the
// binning passes and the per-pixel pass), for compute-only devices and
// lavapipe, whose graphics pipeline is slow.
#include <algorithm>

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "shared/tubes.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {
namespace {

constexpr uint32_t kMaxGroupsX = 65535;                // Vulkan's guaranteed maxComputeWorkGroupCount[0]
constexpr uint64_t kMaxListItems = uint64_t(1) << 28;  // below the offsets pass's saturation (2^31)

struct TileGrid {
  uint32_t x = 0, y = 0;
  uint32_t count() const { return x * y; }
};

class TubeRaycastStage final : public FrameStage {
 public:
  TubeRaycastStage(const GpuTubes* tubes, TubeRaycastOptions options)
      : tubes_(tubes),
        max_items_(std::clamp<uint64_t>(options.max_list_bytes / sizeof(uint32_t), 1, kMaxListItems)) {}
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyBuffer(context, readback_);
    gpu::destroyBuffer(context, tile_lists_);
    gpu::destroyBuffer(context, tile_ends_);
    gpu::destroyBuffer(context, tile_counts_);
    gpu::destroyComputePipeline(context, raycast_);
    gpu::destroyComputePipeline(context, fill_);
    gpu::destroyComputePipeline(context, offsets_);
    gpu::destroyComputePipeline(context, count_);
  }
  uint32_t maxPasses() const override { return 4; }
  bool runs(const FrameContext&) const override { return tubes_ && tubes_->segment_count > 0; }
  bool drawsSurfaces() const override { return true; }
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override {
    gpu::destroyBuffer(context, tile_lists_);
    gpu::destroyBuffer(context, tile_ends_);
    gpu::destroyBuffer(context, tile_counts_);
    wanted_items_ = 0;
    list_capacity_ = 0;
  }

  void record(FrameContext& frame) override {
    makePipelines(frame.context);
    const TileGrid grid{(frame.targets.width + shader::kTubeTileSize - 1) / shader::kTubeTileSize,
                        (frame.targets.height + shader::kTubeTileSize - 1) / shader::kTubeTileSize};
    makeBuffers(frame.context, grid);
    // The previous frame's reads of the counts before they are cleared.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdFillBuffer(frame.cmd, tile_counts_.buffer, 0, VK_WHOLE_SIZE, 0);
    gpu::recordBarrier(frame.cmd, gpu::kTransferToCompute);
    recordBin(frame, count_, "tube bin count", grid);
    recordOffsets(frame, grid);
    recordBin(frame, fill_, "tube bin fill", grid);
    recordRaycast(frame, grid);
    recordReadback(frame, grid);
    recorded_ = true;
  }

  void collect(const gpu::VulkanContext& context, FrameStats& stats) override {
    if (!recorded_) return;
    recorded_ = false;
    uint32_t words[2] = {0, 0};  // overflowing tiles, total items
    gpu::downloadFromBuffer(context, readback_, words, sizeof(words));
    stats.tube_tiles_overflowed = words[0];
    stats.tube_method_bytes = tile_counts_.size + tile_ends_.size + tile_lists_.size;
    // Lists that did not fit: the next frame's buffer holds this frame's
    // total and a quarter more (a moving camera changes it a little).
    if (words[1] > list_capacity_) wanted_items_ = std::min(uint64_t(words[1]) + words[1] / 4, max_items_);
  }

 private:
  void makePipelines(const gpu::VulkanContext& context) {
    if (raycast_.pipeline != VK_NULL_HANDLE) return;
    const gpu::WorkgroupSize bin{shader::kTubeBinGroupSize};
    count_ = gpu::createComputePipeline(context, "tube_bin_count.comp", sizeof(shader::TubeBinPush), bin);
    offsets_ = gpu::createComputePipeline(context, "tube_bin_offsets.comp", sizeof(shader::TubeBinOffsetsPush),
                                          gpu::WorkgroupSize{shader::kTubeScanGroupSize});
    fill_ = gpu::createComputePipeline(context, "tube_bin_fill.comp", sizeof(shader::TubeBinPush), bin);
    raycast_ = gpu::createComputePipeline(context, "tube_raycast.comp", sizeof(shader::TubeRaycastPush),
                                          gpu::WorkgroupSize{shader::kTubeTileSize, shader::kTubeTileSize});
  }

  // The per-tile words at the first frame of a size; the lists at first
  // kTubeTileCapacity items a tile, later the size the last frame asked
  // for. A failed allocation keeps the lists there are (tiles that do not
  // fit overflow: slower, still drawn).
  void makeBuffers(const gpu::VulkanContext& context, TileGrid grid) {
    const VkDeviceSize tiles = grid.count();
    if (!tile_counts_.buffer) {
      // Two more words: the overflowing tiles and the total.
      tile_counts_ = gpu::createBuffer(context, (tiles + 2) * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
      tile_ends_ = gpu::createBuffer(context, tiles * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    }
    if (!tile_lists_.buffer) {
      list_capacity_ = uint32_t(std::min<uint64_t>(tiles * shader::kTubeTileCapacity, max_items_));
      tile_lists_ =
          gpu::createBuffer(context, VkDeviceSize(list_capacity_) * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    } else if (wanted_items_ > list_capacity_) {
      try {
        gpu::Buffer grown =
            gpu::createBuffer(context, VkDeviceSize(wanted_items_) * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
        gpu::destroyBuffer(context, tile_lists_);  // the frame that used it completed (collect)
        tile_lists_ = grown;
        list_capacity_ = uint32_t(wanted_items_);
      } catch (const Error&) {
        max_items_ = list_capacity_;  // the device has no more: do not ask every frame
      }
    }
    wanted_items_ = 0;
  }

  // The fields the binning passes and the ray caster share (their push
  // structs differ in the rest).
  template <typename Push>
  Push tilePush(const FrameContext& frame, TileGrid grid) const {
    Push push{};
    push.camera = frame.targets.camera.address;
    push.nodes = tubes_->nodes.address;
    push.segments = tubes_->segments.address;
    push.tile_counts = tile_counts_.address;
    push.tile_ends = tile_ends_.address;
    push.tile_lists = tile_lists_.address;
    push.sub_segments = tubes_->subSegmentCount();
    push.tiles_x = grid.x;
    push.list_capacity = list_capacity_;
    return push;
  }

  shader::TubeBinPush binPush(const FrameContext& frame, TileGrid grid) const {
    shader::TubeBinPush push = tilePush<shader::TubeBinPush>(frame, grid);
    push.tiles_y = grid.y;
    return push;
  }

  // tube_bin_count.comp or tube_bin_fill.comp: one invocation a sub-segment.
  void recordBin(FrameContext& frame, const gpu::ComputePipeline& pipeline, const char* name, TileGrid grid) {
    gpu::PassScope pass(frame.cmd, frame.timer, name, gpu::kComputeToCompute);
    const uint32_t groups = (tubes_->subSegmentCount() + shader::kTubeBinGroupSize - 1) / shader::kTubeBinGroupSize;
    const uint32_t gx = std::min(groups, kMaxGroupsX), gy = (groups + gx - 1) / gx;
    gpu::recordDispatch(frame.cmd, pipeline, binPush(frame, grid), gx, gy);
  }

  void recordOffsets(FrameContext& frame, TileGrid grid) {
    gpu::PassScope pass(frame.cmd, frame.timer, "tube bin offsets", gpu::kComputeToCompute);
    shader::TubeBinOffsetsPush push{};
    push.tile_counts = tile_counts_.address;
    push.tile_ends = tile_ends_.address;
    push.tiles = grid.count();
    push.list_capacity = list_capacity_;
    gpu::recordDispatch(frame.cmd, offsets_, push, 1, 1);
  }

  void recordRaycast(FrameContext& frame, TileGrid grid) {
    gpu::PassScope pass(frame.cmd, frame.timer, "tube raycast", gpu::kComputeToCompute);
    shader::TubeRaycastPush push = tilePush<shader::TubeRaycastPush>(frame, grid);
    push.surface = frame.targets.surface.address;
    push.width = frame.targets.width;
    push.height = frame.targets.height;
    gpu::recordDispatch(frame.cmd, raycast_, push, grid.x, grid.y);
  }

  // The overflowing tiles and the total to the host, read in collect().
  void recordReadback(FrameContext& frame, TileGrid grid) {
    if (!readback_.buffer) readback_ = gpu::createBuffer(frame.context, 2 * sizeof(uint32_t), gpu::MemoryUse::Readback);
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite,
                                   VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT});
    const VkBufferCopy region{VkDeviceSize(grid.count()) * sizeof(uint32_t), 0, 2 * sizeof(uint32_t)};
    vkCmdCopyBuffer(frame.cmd, tile_counts_.buffer, readback_.buffer, 1, &region);
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                   VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT});
  }

  const GpuTubes* tubes_;
  uint64_t max_items_;                                     // the lists' limit, in items
  gpu::ComputePipeline count_, offsets_, fill_, raycast_;  // made at the first frame with tubes
  gpu::Buffer tile_counts_;  // uint per tile, then the overflowing tiles and the total
  gpu::Buffer tile_ends_;    // uint per tile: each list's end after the fill
  gpu::Buffer tile_lists_;   // list_capacity_ sub-segment indices, tile after tile
  gpu::Buffer readback_;     // the frame's overflowing tiles and total
  uint32_t list_capacity_ = 0;
  uint64_t wanted_items_ = 0;  // the lists' size for the next frame (0: as they are)
  bool recorded_ = false;      // a frame was recorded since the last collect
};

}  // namespace

FrameStageFactory tubeRaycastStage(const GpuTubes* tubes, TubeRaycastOptions options) {
  return [tubes, options](const gpu::VulkanContext&) { return std::make_unique<TubeRaycastStage>(tubes, options); };
}

}  // namespace fibscope
