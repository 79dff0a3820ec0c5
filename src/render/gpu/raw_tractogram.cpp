#include "render/gpu/raw_tractogram.h"

#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>
#include <utility>

#include "core/error.h"
#include "gpu/submit.h"
#include "gpu/vk_check.h"
#include "render/gpu/staged_upload.h"
#include "shared/render_config.h"

namespace fibscope {

namespace {

// Fiber ids are uint and kNoFiberId (2^32 - 1) marks an empty texel; the
// offsets table has streamlines + 1 entries.
constexpr uint64_t kMaxStreamlines = uint64_t(std::numeric_limits<uint32_t>::max()) - 1;
// The raw-compute payload is the global point index (34 bits).
constexpr uint64_t kMaxPoints = uint64_t(1) << shader::kKeyPayloadBits;

// createBuffer refuses 0 bytes; an empty table still gets a valid address.
VkDeviceSize bufferSize(uint64_t bytes) { return std::max<uint64_t>(bytes, 16); }

uint64_t pointBytes(uint64_t points) { return points * 3 * sizeof(float); }

}  // namespace

uint64_t defaultRawChunkBytes(const DeviceLimits& limits) {
  return std::min({limits.max_allocation_bytes, limits.max_buffer_bytes, kRawChunkCapBytes});
}

uint64_t rawChunkBytes(uint64_t points) { return pointBytes(points) + (points + 31) / 32 * sizeof(uint32_t); }

std::vector<RawChunkRange> planRawChunks(const std::string& name, std::span<const uint64_t> offsets,
                                         uint64_t chunk_bytes) {
  std::vector<RawChunkRange> chunks(1);
  const uint64_t streamlines = offsets.empty() ? 0 : offsets.size() - 1;
  for (uint64_t s = 0; s < streamlines; ++s) {
    const uint64_t begin = offsets[s], end = offsets[s + 1];
    if (end < begin)
      fail(name, "streamline offsets decrease at streamline " + std::to_string(s) + " (" + std::to_string(begin) +
                     " then " + std::to_string(end) + ")");
    const uint64_t n = end - begin;
    if (n > std::numeric_limits<uint32_t>::max())
      fail(name, "streamline " + std::to_string(s) + " has " + std::to_string(n) +
                     " points, the lines pipeline draws at most 2^32 - 1 per streamline");
    if (rawChunkBytes(n) > chunk_bytes)
      fail(name, "streamline " + std::to_string(s) + " has " + std::to_string(n) + " points (" +
                     formatBytes(double(rawChunkBytes(n))) + " with its end bits), more than the raw-vertex chunk limit of " +
                     formatBytes(double(chunk_bytes)) + " (a chunk holds whole streamlines)");
    RawChunkRange* current = &chunks.back();
    if (rawChunkBytes(current->point_count + n) > chunk_bytes) {
      // current has points: n alone fits, so the sum only overflows with some.
      chunks.push_back({s, 0, begin, 0});
      current = &chunks.back();
    }
    current->streamline_count += 1;
    current->point_count += n;
  }
  return chunks;
}

uint64_t RawTractogramBytes::largestTable() const { return std::max({chunk_table, offsets, draws, block}); }

RawTractogramBytes rawTractogramBytes(uint64_t streamlines, std::span<const RawChunkRange> chunks) {
  RawTractogramBytes bytes;
  for (const RawChunkRange& chunk : chunks) {
    const uint64_t b = rawChunkBytes(chunk.point_count);
    bytes.points += b;
    bytes.largest_chunk = std::max(bytes.largest_chunk, b);
  }
  bytes.chunk_count = chunks.size();
  bytes.chunk_table = chunks.size() * sizeof(shader::RawChunk);
  bytes.offsets = (streamlines + 1) * sizeof(uint64_t);
  bytes.draws = streamlines * sizeof(VkDrawIndirectCommand);
  bytes.block = sizeof(shader::RawTractogram);
  return bytes;
}

void checkRawTractogramFits(const std::string& name, uint64_t streamlines, uint64_t points,
                            const RawTractogramBytes& bytes, const DeviceLimits& limits) {
  if (streamlines > kMaxStreamlines)
    fail(name, std::to_string(streamlines) + " streamlines: the GPU renderer indexes fibers with 32 bits (at most " +
                   std::to_string(kMaxStreamlines) + ")");
  if (points >= kMaxPoints)
    fail(name, std::to_string(points) + " points: the raw-vertex pipelines index points with " +
                   std::to_string(shader::kKeyPayloadBits) + " bits (fewer than " + std::to_string(kMaxPoints) + ")");
  const uint64_t per_buffer = std::min(limits.max_allocation_bytes, limits.max_buffer_bytes);
  const uint64_t total = bytes.total();
  const bool heap_ok = total <= limits.device_local_heap_bytes;
  if (heap_ok && bytes.largest_chunk <= per_buffer && bytes.largestTable() <= per_buffer) return;
  std::string note = std::to_string(bytes.chunk_count) + (bytes.chunk_count == 1 ? " chunk" : " chunks") +
                     " of points; ";
  if (heap_ok) {
    note = bytes.largest_chunk > per_buffer
               ? "a chunk of points needs one buffer of " + formatBytes(double(bytes.largest_chunk)) + "; "
               : "one table needs one buffer of " + formatBytes(double(bytes.largestTable())) + "; ";
  }
  fail(name, formatBytes(double(total)) + " of raw vertices and tables do not fit on " + limits.device_name + " (" +
                 note + "largest allocation " + formatBytes(double(limits.max_allocation_bytes)) +
                 ", largest buffer " + formatBytes(double(limits.max_buffer_bytes)) + ", device-local heap " +
                 formatBytes(double(limits.device_local_heap_bytes)) + ")");
}

GpuRawTractogram::~GpuRawTractogram() { release(); }

GpuRawTractogram::GpuRawTractogram(GpuRawTractogram&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)),
      chunks_(std::exchange(other.chunks_, {})),
      chunk_table_(std::exchange(other.chunk_table_, {})),
      offsets_(std::exchange(other.offsets_, {})),
      draws_(std::exchange(other.draws_, {})),
      block_buffer_(std::exchange(other.block_buffer_, {})),
      block_(std::exchange(other.block_, {})),
      host_counts_(std::move(other.host_counts_)) {}

GpuRawTractogram& GpuRawTractogram::operator=(GpuRawTractogram&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    chunks_ = std::exchange(other.chunks_, {});
    chunk_table_ = std::exchange(other.chunk_table_, {});
    offsets_ = std::exchange(other.offsets_, {});
    draws_ = std::exchange(other.draws_, {});
    block_buffer_ = std::exchange(other.block_buffer_, {});
    block_ = std::exchange(other.block_, {});
    host_counts_ = std::move(other.host_counts_);
  }
  return *this;
}

void GpuRawTractogram::release() {
  if (!context_) return;
  for (Chunk& chunk : chunks_) gpu::destroyBuffer(*context_, chunk.buffer);
  chunks_.clear();
  for (gpu::Buffer* b : {&chunk_table_, &offsets_, &draws_, &block_buffer_}) gpu::destroyBuffer(*context_, *b);
  context_ = nullptr;
  block_ = {};
  host_counts_.clear();
}

uint64_t GpuRawTractogram::bytes() const {
  uint64_t total = chunk_table_.size + offsets_.size + draws_.size + block_buffer_.size;
  for (const Chunk& chunk : chunks_) total += chunk.buffer.size;
  return total;
}

GpuRawTractogram GpuRawTractogram::upload(const gpu::VulkanContext& context, const Tractogram& tractogram,
                                          const std::string& name, Progress* progress, const DeviceLimits* limits,
                                          uint64_t staging_bytes, uint64_t chunk_bytes) {
  // Sizes first: nothing is allocated before the size check.
  if (tractogram.offsets.empty() || tractogram.offsets.front() != 0) fail(name, "streamline offsets must start at 0");
  const uint64_t streamlines = tractogram.offsets.size() - 1;
  const uint64_t points = tractogram.offsets.back();
  if (tractogram.positions.size() != 3 * points)
    fail(name, std::to_string(tractogram.positions.size()) + " coordinates for " + std::to_string(points) +
                   " points, expected 3 per point");
  const DeviceLimits device_limits = limits ? *limits : deviceLimits(context);
  if (chunk_bytes == 0) chunk_bytes = defaultRawChunkBytes(device_limits);
  const std::vector<RawChunkRange> ranges = planRawChunks(name, tractogram.offsets, chunk_bytes);
  const RawTractogramBytes bytes = rawTractogramBytes(streamlines, ranges);
  checkRawTractogramFits(name, streamlines, points, bytes, device_limits);

  uint64_t segments = 0;
  for (uint64_t s = 0; s < streamlines; ++s) {
    const uint64_t n = tractogram.offsets[s + 1] - tractogram.offsets[s];
    segments += n > 0 ? n - 1 : 0;
  }

  GpuRawTractogram result;
  result.context_ = &context;
  result.chunks_.reserve(ranges.size());
  for (const RawChunkRange& range : ranges) {
    Chunk chunk;
    chunk.buffer = gpu::createBuffer(context, bufferSize(rawChunkBytes(range.point_count)), gpu::MemoryUse::DeviceLocal);
    chunk.entry.points = chunk.buffer.address;
    chunk.entry.ends = chunk.buffer.address + pointBytes(range.point_count);
    chunk.entry.first_point = range.first_point;
    chunk.entry.point_count = range.point_count;
    chunk.entry.first_streamline = uint32_t(range.first_streamline);
    chunk.entry.streamline_count = uint32_t(range.streamline_count);
    result.chunks_.push_back(chunk);
  }
  result.chunk_table_ = gpu::createBuffer(context, bufferSize(bytes.chunk_table), gpu::MemoryUse::DeviceLocal);
  result.offsets_ = gpu::createBuffer(context, bufferSize(bytes.offsets), gpu::MemoryUse::DeviceLocal);
  result.draws_ = gpu::createBuffer(context, bufferSize(bytes.draws), gpu::MemoryUse::DeviceLocal,
                                    VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  result.block_buffer_ = gpu::createBuffer(context, bufferSize(bytes.block), gpu::MemoryUse::DeviceLocal);
  shader::RawTractogram& block = result.block_;
  block.chunks = result.chunk_table_.address;
  block.offsets = result.offsets_.address;
  block.draws = result.draws_.address;
  block.point_count = points;
  block.segment_count = segments;
  block.streamline_count = uint32_t(streamlines);
  block.chunk_count = uint32_t(ranges.size());
  std::vector<shader::RawChunk> table;
  table.reserve(result.chunks_.size());
  for (const Chunk& chunk : result.chunks_) table.push_back(chunk.entry);

  const VkPhysicalDeviceFeatures& features = context.enabledFeatures();
  if (!features.multiDrawIndirect || !features.drawIndirectFirstInstance) {
    result.host_counts_.resize(streamlines);
    for (uint64_t s = 0; s < streamlines; ++s)
      result.host_counts_[s] = uint32_t(tractogram.offsets[s + 1] - tractogram.offsets[s]);
  }

  // One draw per streamline; offsets are whole commands because the
  // staging size is a multiple of 16 bytes.
  const ChunkSource draws = [&](uint8_t* out, uint64_t offset, uint64_t piece) {
    const uint64_t first = offset / sizeof(VkDrawIndirectCommand);
    const uint64_t count = piece / sizeof(VkDrawIndirectCommand);
    auto* commands = reinterpret_cast<VkDrawIndirectCommand*>(out);
    for (uint64_t k = 0; k < count; ++k) {
      const uint64_t s = first + k;
      commands[k] = {uint32_t(tractogram.offsets[s + 1] - tractogram.offsets[s]), 1, 0, uint32_t(s)};
    }
  };

  if (progress) progress->setTotal(double(bytes.total()));
  // A multiple of 16 bytes (whole draw commands, whole words).
  const uint64_t staging_size =
      std::clamp<uint64_t>(std::max(bytes.largest_chunk, bytes.largestTable()), 16, std::max<uint64_t>(staging_bytes, 16)) /
      16 * 16;
  gpu::Buffer staging = gpu::createBuffer(context, staging_size, gpu::MemoryUse::Upload);
  try {
    for (const Chunk& chunk : result.chunks_) {
      const shader::RawChunk& entry = chunk.entry;
      const uint64_t point_bytes = pointBytes(entry.point_count);
      uploadChunked(context, staging, chunk.buffer, point_bytes,
                    bytesOf(tractogram.positions.data() + 3 * entry.first_point), progress);
      // End bits: word w covers the chunk's points [32 w, 32 w + 32); its
      // streamlines are walked once over all pieces (pieces come in order).
      // Staging pieces are multiples of 16 bytes, so each starts on a word.
      uint64_t next = entry.first_streamline;
      const uint64_t chunk_end = uint64_t(entry.first_streamline) + entry.streamline_count;
      const ChunkSource ends = [&](uint8_t* out, uint64_t offset, uint64_t piece) {
        auto* words = reinterpret_cast<uint32_t*>(out);
        std::memset(words, 0, size_t(piece));
        const uint64_t first_local = offset / 4 * 32, end_local = (offset + piece) / 4 * 32;
        for (; next < chunk_end; ++next) {
          const uint64_t end = tractogram.offsets[next + 1];
          if (end == tractogram.offsets[next]) continue;  // no points, no end
          const uint64_t last = end - 1 - entry.first_point;
          if (last >= end_local) break;  // in a later piece
          if (last >= first_local) words[(last - first_local) / 32] |= uint32_t(1) << (last % 32);
        }
      };
      uploadChunked(context, staging, chunk.buffer, rawChunkBytes(entry.point_count) - point_bytes, ends, progress,
                    point_bytes);
    }
    uploadChunked(context, staging, result.chunk_table_, bytes.chunk_table, bytesOf(table.data()), progress);
    uploadChunked(context, staging, result.offsets_, bytes.offsets, bytesOf(tractogram.offsets.data()), progress);
    uploadChunked(context, staging, result.draws_, bytes.draws, draws, progress);
    uploadChunked(context, staging, result.block_buffer_, bytes.block, bytesOf(&block), progress);
  } catch (...) {
    gpu::destroyBuffer(context, staging);
    throw;
  }
  gpu::destroyBuffer(context, staging);
  return result;
}

}  // namespace fibscope
