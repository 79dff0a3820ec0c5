// An uncompressed tractogram in device-local GPU buffers, the input of the
// two baseline pipelines (DESIGN.md section 6): `lines` and `raw-compute`.
// The points as float xyz (Tractogram::positions as is, 12 bytes a point),
// the streamline offsets as uint64, a one-bit-per-point table of streamline
// ends, one VkDrawIndirectCommand per streamline, and the RawTractogram
// block the shaders read them through (shaders/shared/raw_tractogram.h).
//
// As for GpuDataset, the size is checked against the device before
// anything is allocated: buffers are reached by device address, so the
// storage-buffer range (128 MiB on lavapipe) does not matter, but the
// largest allocation, the largest buffer and the device-local heap do.
// Buffers are filled through one bounded staging buffer; the draw commands
// and the end bits are generated chunk by chunk straight into it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/progress.h"
#include "core/tractogram.h"
#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "render/gpu_dataset.h"
#include "shared/raw_tractogram.h"

namespace fibscope {

// Bytes of each buffer of a raw tractogram.
struct RawTractogramBytes {
  uint64_t points = 0;   // 12 per point
  uint64_t offsets = 0;  // 8 per streamline + 8
  uint64_t ends = 0;     // one bit per point, in uint words
  uint64_t draws = 0;    // 16 per streamline
  uint64_t block = 0;

  uint64_t total() const { return points + offsets + ends + draws + block; }
  uint64_t largest() const;
};
RawTractogramBytes rawTractogramBytes(uint64_t streamlines, uint64_t points);

// Throws Error "<name>: X of raw vertices and tables do not fit on DEVICE
// (...)" (one line) when the total exceeds the device-local heap or one
// buffer exceeds the largest allocation or buffer; also for 2^32 - 1
// streamlines or more (fiber ids are uint, kNoFiberId reserved) and for
// 2^34 points or more (the visibility key's payload).
void checkRawTractogramFits(const std::string& name, uint64_t streamlines, uint64_t points,
                            const RawTractogramBytes& bytes, const DeviceLimits& limits);

class GpuRawTractogram {
 public:
  GpuRawTractogram() = default;
  ~GpuRawTractogram();
  GpuRawTractogram(GpuRawTractogram&& other) noexcept;
  GpuRawTractogram& operator=(GpuRawTractogram&& other) noexcept;
  GpuRawTractogram(const GpuRawTractogram&) = delete;
  GpuRawTractogram& operator=(const GpuRawTractogram&) = delete;

  // Uploads the points and streamlines of `tractogram` (data arrays are not
  // uploaded). `name` stands for the file in messages. Throws Error naming
  // it when the tractogram is inconsistent (offsets not increasing from 0
  // to the point count, positions not 3 per point), when a streamline has
  // 2^32 points or more (a draw's vertex count), or when it does not fit
  // (checkRawTractogramFits, before any allocation; `limits` replaces the
  // device's own, for tests). `progress` counts the bytes uploaded.
  static GpuRawTractogram upload(const gpu::VulkanContext& context, const Tractogram& tractogram,
                                 const std::string& name, Progress* progress = nullptr,
                                 const DeviceLimits* limits = nullptr, uint64_t staging_bytes = kDatasetStagingBytes);

  const shader::RawTractogram& block() const { return block_; }
  VkDeviceAddress blockAddress() const { return block_buffer_.address; }
  uint64_t bytes() const;
  uint32_t streamlineCount() const { return block_.streamline_count; }
  uint64_t pointCount() const { return block_.point_count; }
  uint64_t segmentCount() const { return block_.segment_count; }

  const gpu::Buffer& points() const { return points_; }
  const gpu::Buffer& offsets() const { return offsets_; }
  const gpu::Buffer& ends() const { return ends_; }
  // VkDrawIndirectCommand per streamline (INDIRECT_BUFFER usage).
  const gpu::Buffer& draws() const { return draws_; }
  const gpu::Buffer& blockBuffer() const { return block_buffer_; }
  // The points per streamline on the host, kept only when the device lacks
  // multiDrawIndirect or drawIndirectFirstInstance: the lines pass then
  // records one direct draw per streamline. Empty otherwise.
  const std::vector<uint32_t>& hostCounts() const { return host_counts_; }

 private:
  void release();

  const gpu::VulkanContext* context_ = nullptr;
  gpu::Buffer points_, offsets_, ends_, draws_, block_buffer_;
  shader::RawTractogram block_{};
  std::vector<uint32_t> host_counts_;
};

}  // namespace fibscope
