// A whole dataset in device-local GPU buffers (DESIGN.md section 6): the
// fiblet records as stored, the per-fiblet fiber index, the direction
// table, the per-fiber tables, and the FibletDataset block the shaders read
// them through (shaders/shared/fiblet_dataset.h).
//
// The size is checked against the device before anything is allocated or
// read: a dataset that does not fit is a one-line Error naming the file,
// the bytes needed and what the device has. Streaming a dataset larger than
// the device is not implemented yet.
//
// Sections are copied through one bounded staging buffer, so a 10 GB
// section needs no 10 GB of host-visible memory. The bounds buffer (16
// bytes per fiblet, render/gpu/fiblet_bounds.h) is allocated with the rest
// but filled only when the occlusion cull first needs it: decoding every
// fiblet takes ~1 us a fiblet on lavapipe (0.3 s for the 246 MB tckgen
// file), which a one-frame `render` with frustum culling, or a viewer's
// upload on the main thread, should not pay.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "codec/codec_params.h"
#include "codec/fbl_file.h"
#include "codec/fiblet_decoder.h"
#include "core/progress.h"
#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/fiblet_bounds.h"
#include "shared/fiblet_dataset.h"

namespace fibscope {

// The staging buffer's default size: large enough that the per-copy
// submission is noise (a few ms per 64 MiB even on lavapipe), small enough
// to find in any host-visible heap.
inline constexpr uint64_t kDatasetStagingBytes = uint64_t(64) << 20;

// What bounds a dataset on a device.
struct DeviceLimits {
  std::string device_name;
  uint64_t device_local_heap_bytes = 0;  // the largest DEVICE_LOCAL heap
  uint64_t max_allocation_bytes = 0;     // maxMemoryAllocationSize (Vulkan 1.1)
  uint64_t max_buffer_bytes = 0;         // maxBufferSize (Vulkan 1.3, maintenance4)
};

// The context's device's limits.
DeviceLimits deviceLimits(const gpu::VulkanContext& context);

// Bytes of each buffer of a dataset of `fibers` fibers and `fiblets`
// fiblets with `record_bytes` bytes per record.
struct DatasetBytes {
  uint64_t records = 0;
  uint64_t fiblet_fiber = 0;
  uint64_t directions = 0;
  uint64_t fiber_first_fiblet = 0;
  uint64_t fiber_length = 0;
  uint64_t block = 0;
  uint64_t bounds = 0;  // computed on the device, not uploaded

  uint64_t total() const {
    return records + fiblet_fiber + directions + fiber_first_fiblet + fiber_length + block + bounds;
  }
  uint64_t largest() const;
};
DatasetBytes datasetBytes(uint64_t fibers, uint64_t fiblets, uint32_t record_bytes);

// Throws Error "<name>: X of fiblets and tables do not fit on DEVICE
// (largest allocation A, largest buffer B, device-local heap H); streaming
// is not implemented yet" when the total exceeds the heap or one buffer
// exceeds the largest allocation or buffer; also when the dataset has
// 2^32 fiblets or more (the shaders index fiblets with uint).
void checkDatasetFits(const std::string& name, uint64_t fibers, uint64_t fiblets, const DatasetBytes& bytes,
                      const DeviceLimits& limits);

class GpuDataset {
 public:
  GpuDataset() = default;
  ~GpuDataset();
  GpuDataset(GpuDataset&& other) noexcept;
  GpuDataset& operator=(GpuDataset&& other) noexcept;
  GpuDataset(const GpuDataset&) = delete;
  GpuDataset& operator=(const GpuDataset&) = delete;

  // Uploads an opened .fbl. Throws Error naming the file when the dataset
  // does not fit (before any allocation or section read; `limits` replaces
  // the device's own, for tests), when a section is missing, of the wrong
  // type or size, or fails its checksum, or when fiber_first_fiblet is not
  // increasing from 0 to the fiblet count. `progress` (optional) counts the
  // bytes uploaded (not the bounds buffer: filled on the device later);
  // sections are copied `staging_bytes` at a time.
  static GpuDataset upload(const gpu::VulkanContext& context, const FblFile& file, Progress* progress = nullptr,
                           const DeviceLimits* limits = nullptr, uint64_t staging_bytes = kDatasetStagingBytes);

  // Uploads a tractogram encoded in memory (a whole one: fiblet_base 0),
  // with its fibers' lengths in mm (one per fiber). `name` stands for the
  // file in messages.
  static GpuDataset upload(const gpu::VulkanContext& context, const EncodedFiblets& fiblets, const CodecParams& params,
                           std::span<const float> fiber_length_mm, const std::string& name,
                           Progress* progress = nullptr, const DeviceLimits* limits = nullptr,
                           uint64_t staging_bytes = kDatasetStagingBytes);
  // The same for a tractogram encoded in parts (consecutive runs of whole
  // fibers encoded apart, in order, each part's fiber_first_fiblet counted
  // from its own first record), uploaded as if joined, without joining
  // them in memory first.
  static GpuDataset upload(const gpu::VulkanContext& context, std::span<const EncodedFiblets* const> parts,
                           const CodecParams& params, std::span<const float> fiber_length_mm,
                           const std::string& name, Progress* progress = nullptr,
                           const DeviceLimits* limits = nullptr, uint64_t staging_bytes = kDatasetStagingBytes);

  // The block as uploaded (addresses of this dataset's buffers).
  const shader::FibletDataset& block() const { return block_; }
  // The device address of the block's buffer, for push constants.
  VkDeviceAddress blockAddress() const { return block_buffer_.address; }
  // Bytes of device memory held (the sum of the buffer sizes).
  uint64_t bytes() const;

  // The buffers, for tests and passes that copy from them.
  const gpu::Buffer& records() const { return records_; }
  const gpu::Buffer& fibletFiber() const { return fiblet_fiber_; }
  const gpu::Buffer& directions() const { return directions_; }
  const gpu::Buffer& fiberFirstFiblet() const { return fiber_first_fiblet_; }
  const gpu::Buffer& fiberLength() const { return fiber_length_; }
  const gpu::Buffer& blockBuffer() const { return block_buffer_; }
  // vec4 per fiblet: world centre and radius (< 0: draws nothing).
  const gpu::Buffer& fibletBounds() const { return bounds_; }

  // Whether the spheres have been computed (computeFibletBounds, or a
  // frame's recordFibletBoundsOnce).
  bool fibletBoundsReady() const { return bounds_ready_; }
  // Computes the spheres now (one submission, waits) and points the block
  // at them.
  void computeFibletBounds();
  // For the frame renderer, before its first occlusion cull of this
  // dataset: records the pass that fills the spheres and the update of the
  // block's fiblet_bounds, with the barriers for the cull that follows, and
  // counts them as ready (the caller submits `cmd`). Nothing when ready.
  // Logically const: the spheres are a cache of the records.
  void recordFibletBoundsOnce(VkCommandBuffer cmd, const FibletBoundsPass& pass) const;
  // Whether the block names the (computed) bounds buffer. False makes the
  // cull fall back to the looser bound from the record, for comparisons;
  // rewrites the block buffer, so the GPU must not be using it.
  void useFibletBounds(bool use);

 private:
  struct Source;
  void fill(const gpu::VulkanContext& context, const Source& source, const DatasetBytes& bytes, Progress* progress,
            uint64_t staging_bytes);
  void release();

  const gpu::VulkanContext* context_ = nullptr;
  gpu::Buffer records_, fiblet_fiber_, directions_, fiber_first_fiblet_, fiber_length_, block_buffer_, bounds_;
  // The block as on the device: fiblet_bounds is 0 until the spheres are
  // computed (mutable with bounds_ready_: recordFibletBoundsOnce).
  mutable shader::FibletDataset block_{};
  mutable bool bounds_ready_ = false;
};

}  // namespace fibscope
