// An uncompressed tractogram in device-local GPU buffers, the input of the
// two baseline pipelines (DESIGN.md section 6): `lines` and `raw-compute`.
// The points as float xyz (Tractogram::positions as is, 12 bytes a point)
// in chunks of whole streamlines, each chunk one buffer followed by its
// one-bit-per-point table of streamline ends; the chunk table; the
// streamline offsets as uint64; one VkDrawIndirectCommand per streamline;
// and the RawTractogram block the shaders read them through
// (shaders/shared/raw_tractogram.h).
//
// Why chunks: one buffer may exceed neither maxMemoryAllocationSize (4 GiB
// on NVIDIA, 2 GiB on lavapipe) nor maxBufferSize, and the paper's 500 k
// fiber tractogram has 4.8 GiB of vertices. A chunk holds whole streamlines
// so that the lines pipeline draws each chunk's streamlines from its own
// buffer and no raw-compute segment crosses two chunks. Everything that
// grows with the points is split (the points and their end bits); the
// tables that grow with the streamlines stay global: 24 bytes a streamline
// (offsets 8, draw 16), 240 MB for 10 M streamlines, well under the 1 GiB
// every Vulkan device must allow in one allocation, and each is still
// checked against the device. Buffers are reached by device address, so
// the storage-buffer range (maxStorageBufferRange, 128 MiB on lavapipe),
// which bounds descriptor ranges only, does not matter.
//
// As for GpuDataset, the size is checked against the device before
// anything is allocated. Buffers are filled through one bounded staging
// buffer; the draw commands and the end bits are generated piece by piece
// straight into it.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/progress.h"
#include "core/tractogram.h"
#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/dataset.h"
#include "shared/raw_tractogram.h"

namespace fibscope {

// The largest chunk by default, below the device's own limits: the
// allocation every Vulkan device must allow (maxMemoryAllocationSize >=
// 2^30). Larger chunks would save nothing measurable (a chunk costs one
// dispatch and one indirect draw a frame) and are harder for a driver to
// place in a fragmented heap.
inline constexpr uint64_t kRawChunkCapBytes = uint64_t(1) << 30;

// min(largest allocation, largest buffer, kRawChunkCapBytes).
uint64_t defaultRawChunkBytes(const DeviceLimits& limits);

// Bytes of a chunk buffer of `points` points: 12 per point, then the end
// bits in whole uint words.
uint64_t rawChunkBytes(uint64_t points);

// Streamlines [first_streamline, + streamline_count) and their points
// [first_point, + point_count).
struct RawChunkRange {
  uint64_t first_streamline = 0;
  uint64_t streamline_count = 0;
  uint64_t first_point = 0;
  uint64_t point_count = 0;
};

// Splits the streamlines of `offsets` (streamline s owns points
// [offsets[s], offsets[s + 1]), offsets[0] = 0) greedily, in order, into
// chunks whose rawChunkBytes are at most `chunk_bytes`; streamlines of no
// points join the current chunk. Always at least one chunk (an empty one
// for no points). Throws Error "<name>: streamline S has N points (X), more
// than the raw-vertex chunk limit of Y ..." (one line) when one streamline
// alone exceeds the limit, and names the streamline where the offsets
// decrease or a streamline has 2^32 points or more (a draw's vertexCount).
std::vector<RawChunkRange> planRawChunks(const std::string& name, std::span<const uint64_t> offsets,
                                         uint64_t chunk_bytes);

// Bytes of each buffer of a raw tractogram.
struct RawTractogramBytes {
  uint64_t points = 0;         // the chunks' buffers: 12 per point plus end bits
  uint64_t largest_chunk = 0;  // the largest chunk buffer
  uint64_t chunk_count = 0;
  uint64_t chunk_table = 0;  // 40 per chunk
  uint64_t offsets = 0;      // 8 per streamline + 8
  uint64_t draws = 0;        // 16 per streamline
  uint64_t block = 0;

  uint64_t total() const { return points + chunk_table + offsets + draws + block; }
  // The largest buffer that is not a chunk of points.
  uint64_t largestTable() const;
};
RawTractogramBytes rawTractogramBytes(uint64_t streamlines, std::span<const RawChunkRange> chunks);

// Throws Error "<name>: X of raw vertices and tables do not fit on DEVICE
// (...)" (one line) when the total exceeds the device-local heap or one
// buffer (a chunk or a table) exceeds the largest allocation or buffer;
// also for 2^32 - 1 streamlines or more (fiber ids are uint, kNoFiberId
// reserved) and for 2^34 points or more (the visibility key's payload).
void checkRawTractogramFits(const std::string& name, uint64_t streamlines, uint64_t points,
                            const RawTractogramBytes& bytes, const DeviceLimits& limits);

class GpuRawTractogram {
 public:
  // One chunk of points: its buffer (points, then end bits) and its entry
  // in the chunk table.
  struct Chunk {
    gpu::Buffer buffer;
    shader::RawChunk entry{};
  };

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
  // 2^32 points or more (a draw's vertex count) or does not fit in one
  // chunk, or when the whole does not fit (checkRawTractogramFits, before
  // any allocation; `limits` replaces the device's own, for tests).
  // `progress` counts the bytes uploaded. `chunk_bytes` bounds each chunk
  // buffer; 0: defaultRawChunkBytes of the limits (tests force small ones).
  static GpuRawTractogram upload(const gpu::VulkanContext& context, const Tractogram& tractogram,
                                 const std::string& name, Progress* progress = nullptr,
                                 const DeviceLimits* limits = nullptr, uint64_t staging_bytes = kDatasetStagingBytes,
                                 uint64_t chunk_bytes = 0);

  const shader::RawTractogram& block() const { return block_; }
  VkDeviceAddress blockAddress() const { return block_buffer_.address; }
  uint64_t bytes() const;
  uint32_t streamlineCount() const { return block_.streamline_count; }
  uint64_t pointCount() const { return block_.point_count; }
  uint64_t segmentCount() const { return block_.segment_count; }

  // The chunks in point order (at least one once uploaded).
  uint32_t chunkCount() const { return uint32_t(chunks_.size()); }
  const Chunk& chunk(uint32_t c) const { return chunks_[c]; }
  const gpu::Buffer& chunkTable() const { return chunk_table_; }
  const gpu::Buffer& offsets() const { return offsets_; }
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
  std::vector<Chunk> chunks_;
  gpu::Buffer chunk_table_, offsets_, draws_, block_buffer_;
  shader::RawTractogram block_{};
  std::vector<uint32_t> host_counts_;
};

}  // namespace fibscope
