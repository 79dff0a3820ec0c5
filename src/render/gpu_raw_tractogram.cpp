#include "render/gpu_raw_tractogram.h"

#include <algorithm>
#include <cstring>
#include <functional>
#include <limits>
#include <utility>

#include "core/error.h"
#include "gpu/submit.h"
#include "gpu/vk_check.h"
#include "render/gpu_staged_upload.h"
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


}  // namespace

uint64_t RawTractogramBytes::largest() const { return std::max({points, offsets, ends, draws, block}); }

RawTractogramBytes rawTractogramBytes(uint64_t streamlines, uint64_t points) {
  RawTractogramBytes bytes;
  bytes.points = points * 3 * sizeof(float);
  bytes.offsets = (streamlines + 1) * sizeof(uint64_t);
  bytes.ends = (points + 31) / 32 * sizeof(uint32_t);
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
  if (total <= limits.device_local_heap_bytes && bytes.largest() <= per_buffer) return;
  const std::string buffer_note =
      total <= limits.device_local_heap_bytes
          ? std::string(bytes.largest() == bytes.points ? "the points need" : "one table needs") + " one buffer of " +
                formatBytes(double(bytes.largest())) + "; "
          : std::string();
  fail(name, formatBytes(double(total)) + " of raw vertices and tables do not fit on " + limits.device_name + " (" +
                 buffer_note + "largest allocation " + formatBytes(double(limits.max_allocation_bytes)) +
                 ", largest buffer " + formatBytes(double(limits.max_buffer_bytes)) + ", device-local heap " +
                 formatBytes(double(limits.device_local_heap_bytes)) + ")");
}

GpuRawTractogram::~GpuRawTractogram() { release(); }

GpuRawTractogram::GpuRawTractogram(GpuRawTractogram&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)),
      points_(std::exchange(other.points_, {})),
      offsets_(std::exchange(other.offsets_, {})),
      ends_(std::exchange(other.ends_, {})),
      draws_(std::exchange(other.draws_, {})),
      block_buffer_(std::exchange(other.block_buffer_, {})),
      block_(std::exchange(other.block_, {})),
      host_counts_(std::move(other.host_counts_)) {}

GpuRawTractogram& GpuRawTractogram::operator=(GpuRawTractogram&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    points_ = std::exchange(other.points_, {});
    offsets_ = std::exchange(other.offsets_, {});
    ends_ = std::exchange(other.ends_, {});
    draws_ = std::exchange(other.draws_, {});
    block_buffer_ = std::exchange(other.block_buffer_, {});
    block_ = std::exchange(other.block_, {});
    host_counts_ = std::move(other.host_counts_);
  }
  return *this;
}

void GpuRawTractogram::release() {
  if (!context_) return;
  for (gpu::Buffer* b : {&points_, &offsets_, &ends_, &draws_, &block_buffer_}) gpu::destroyBuffer(*context_, *b);
  context_ = nullptr;
  block_ = {};
  host_counts_.clear();
}

uint64_t GpuRawTractogram::bytes() const {
  return points_.size + offsets_.size + ends_.size + draws_.size + block_buffer_.size;
}

GpuRawTractogram GpuRawTractogram::upload(const gpu::VulkanContext& context, const Tractogram& tractogram,
                                          const std::string& name, Progress* progress, const DeviceLimits* limits,
                                          uint64_t staging_bytes) {
  // Sizes first: nothing is allocated before the size check.
  if (tractogram.offsets.empty() || tractogram.offsets.front() != 0) fail(name, "streamline offsets must start at 0");
  const uint64_t streamlines = tractogram.offsets.size() - 1;
  const uint64_t points = tractogram.offsets.back();
  if (tractogram.positions.size() != 3 * points)
    fail(name, std::to_string(tractogram.positions.size()) + " coordinates for " + std::to_string(points) +
                   " points, expected 3 per point");
  const RawTractogramBytes bytes = rawTractogramBytes(streamlines, points);
  checkRawTractogramFits(name, streamlines, points, bytes, limits ? *limits : deviceLimits(context));

  uint64_t segments = 0;
  for (uint64_t s = 0; s < streamlines; ++s) {
    const uint64_t begin = tractogram.offsets[s], end = tractogram.offsets[s + 1];
    if (end < begin)
      fail(name, "streamline offsets decrease at streamline " + std::to_string(s) + " (" + std::to_string(begin) +
                     " then " + std::to_string(end) + ")");
    if (end - begin > std::numeric_limits<uint32_t>::max())
      fail(name, "streamline " + std::to_string(s) + " has " + std::to_string(end - begin) +
                     " points, the lines pipeline draws at most 2^32 - 1 per streamline");
    segments += end > begin ? end - begin - 1 : 0;
  }

  GpuRawTractogram result;
  result.context_ = &context;
  result.points_ = gpu::createBuffer(context, bufferSize(bytes.points), gpu::MemoryUse::DeviceLocal);
  result.offsets_ = gpu::createBuffer(context, bufferSize(bytes.offsets), gpu::MemoryUse::DeviceLocal);
  result.ends_ = gpu::createBuffer(context, bufferSize(bytes.ends), gpu::MemoryUse::DeviceLocal);
  result.draws_ = gpu::createBuffer(context, bufferSize(bytes.draws), gpu::MemoryUse::DeviceLocal,
                                    VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  result.block_buffer_ = gpu::createBuffer(context, bufferSize(bytes.block), gpu::MemoryUse::DeviceLocal);
  shader::RawTractogram& block = result.block_;
  block.points = result.points_.address;
  block.offsets = result.offsets_.address;
  block.ends = result.ends_.address;
  block.draws = result.draws_.address;
  block.point_count = points;
  block.segment_count = segments;
  block.streamline_count = uint32_t(streamlines);

  const VkPhysicalDeviceFeatures& features = context.enabledFeatures();
  if (!features.multiDrawIndirect || !features.drawIndirectFirstInstance) {
    result.host_counts_.resize(streamlines);
    for (uint64_t s = 0; s < streamlines; ++s)
      result.host_counts_[s] = uint32_t(tractogram.offsets[s + 1] - tractogram.offsets[s]);
  }

  // One draw per streamline; offsets are whole commands because the
  // staging size is a multiple of 16 bytes.
  const ChunkSource draws = [&](uint8_t* out, uint64_t offset, uint64_t chunk) {
    const uint64_t first = offset / sizeof(VkDrawIndirectCommand);
    const uint64_t count = chunk / sizeof(VkDrawIndirectCommand);
    auto* commands = reinterpret_cast<VkDrawIndirectCommand*>(out);
    for (uint64_t k = 0; k < count; ++k) {
      const uint64_t s = first + k;
      commands[k] = {uint32_t(tractogram.offsets[s + 1] - tractogram.offsets[s]), 1, 0, uint32_t(s)};
    }
  };
  // End bits: word w covers points [32 w, 32 w + 32); the streamlines are
  // walked once over all chunks (chunks come in order).
  uint64_t next_streamline = 0;
  const ChunkSource ends = [&](uint8_t* out, uint64_t offset, uint64_t chunk) {
    auto* words = reinterpret_cast<uint32_t*>(out);
    std::memset(words, 0, size_t(chunk));
    const uint64_t first_point = offset / 4 * 32, end_point = (offset + chunk) / 4 * 32;
    for (; next_streamline < streamlines; ++next_streamline) {
      const uint64_t end = tractogram.offsets[next_streamline + 1];
      if (end == tractogram.offsets[next_streamline]) continue;  // no points, no end
      const uint64_t last = end - 1;
      if (last >= end_point) break;  // in a later chunk
      if (last >= first_point) words[(last - first_point) / 32] |= uint32_t(1) << (last % 32);
    }
  };

  if (progress) progress->setTotal(double(bytes.total()));
  // A multiple of 16 bytes (whole draw commands, whole words).
  const uint64_t staging_size =
      std::clamp<uint64_t>(bytes.largest(), 16, std::max<uint64_t>(staging_bytes, 16)) / 16 * 16;
  gpu::Buffer staging = gpu::createBuffer(context, staging_size, gpu::MemoryUse::Upload);
  try {
    uploadChunked(context, staging, result.points_, bytes.points, bytesOf(tractogram.positions.data()), progress);
    uploadChunked(context, staging, result.offsets_, bytes.offsets, bytesOf(tractogram.offsets.data()), progress);
    uploadChunked(context, staging, result.ends_, bytes.ends, ends, progress);
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
