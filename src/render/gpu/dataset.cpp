#include "render/gpu/dataset.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "codec/fbl_codec.h"
#include "core/error.h"
#include "gpu/submit.h"
#include "gpu/vk_check.h"
#include "render/gpu/fiblet_bounds.h"
#include "render/gpu/staged_upload.h"

namespace fibscope {

namespace {

// Shaders index fiblets and fibers with uint.
constexpr uint64_t kMaxCount = uint64_t(std::numeric_limits<uint32_t>::max());

// createBuffer refuses 0 bytes; an empty table still gets a valid address.
VkDeviceSize bufferSize(uint64_t bytes) { return std::max<uint64_t>(bytes, 4); }

// The per-fiber tables the shaders need, derived from the first fiblet of
// each fiber (fibers + 1 entries, the last one the fiblet count).
struct FiberTables {
  std::vector<uint32_t> first;         // fibers + 1
  std::vector<uint32_t> fiblet_fiber;  // fiblets
};

// `first` holds `fibers` + 1 entries. Fails naming `name` unless they run
// from 0 to `fiblets` without decreasing (a fiber of no fiblets is allowed:
// it owns an empty range).
template <typename T>
FiberTables deriveFiberTables(const std::string& name, std::span<const T> first, uint64_t fiblets) {
  const size_t fibers = first.size() - 1;
  if (uint64_t(first[0]) != 0)
    fail(name, "fiber_first_fiblet[0] is " + std::to_string(uint64_t(first[0])) + ", expected 0");
  if (uint64_t(first[fibers]) != fiblets)
    fail(name, "fiber_first_fiblet ends at " + std::to_string(uint64_t(first[fibers])) +
                   ", expected the fiblet count " + std::to_string(fiblets));
  FiberTables tables;
  tables.first.resize(fibers + 1);
  tables.fiblet_fiber.resize(fiblets);
  for (size_t f = 0; f < fibers; ++f) {
    const uint64_t begin = first[f], end = first[f + 1];
    if (end < begin)
      fail(name, "fiber_first_fiblet decreases at fiber " + std::to_string(f + 1) + " (" + std::to_string(begin) +
                     " then " + std::to_string(end) + ")");
    // Checked before the fill: a later decrease would come too late.
    if (end > fiblets)
      fail(name, "fiber_first_fiblet[" + std::to_string(f + 1) + "] is " + std::to_string(end) +
                     ", beyond the fiblet count " + std::to_string(fiblets));
    tables.first[f] = uint32_t(begin);
    std::fill(tables.fiblet_fiber.begin() + ptrdiff_t(begin), tables.fiblet_fiber.begin() + ptrdiff_t(end),
              uint32_t(f));
  }
  tables.first[fibers] = uint32_t(fiblets);
  return tables;
}


}  // namespace

DeviceLimits deviceLimits(const gpu::VulkanContext& context) {
  DeviceLimits limits;
  limits.device_name = context.info().name;
  const VkPhysicalDeviceMemoryProperties& memory = context.memoryProperties();
  uint64_t largest_heap = 0;
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    largest_heap = std::max<uint64_t>(largest_heap, memory.memoryHeaps[h].size);
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      limits.device_local_heap_bytes = std::max<uint64_t>(limits.device_local_heap_bytes, memory.memoryHeaps[h].size);
  }
  // Vulkan requires a device-local heap; should a driver not flag one, the
  // largest heap is the best estimate of what the buffers can use.
  if (limits.device_local_heap_bytes == 0) limits.device_local_heap_bytes = largest_heap;

  VkPhysicalDeviceVulkan13Properties vulkan13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES};
  VkPhysicalDeviceVulkan11Properties vulkan11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES};
  vulkan11.pNext = &vulkan13;
  VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  properties.pNext = &vulkan11;
  vkGetPhysicalDeviceProperties2(context.physicalDevice(), &properties);
  limits.max_allocation_bytes = vulkan11.maxMemoryAllocationSize;
  limits.max_buffer_bytes = vulkan13.maxBufferSize;
  return limits;
}

uint64_t DatasetBytes::largest() const {
  return std::max({records, fiblet_fiber, directions, fiber_first_fiblet, fiber_length, block, bounds});
}

DatasetBytes datasetBytes(uint64_t fibers, uint64_t fiblets, uint32_t record_bytes) {
  DatasetBytes bytes;
  bytes.records = fiblets * record_bytes;
  bytes.fiblet_fiber = fiblets * sizeof(uint32_t);
  bytes.directions = shader::kFibletCodeCount * 4 * sizeof(shader::vec4);  // directions, then L_c as 3 vec4
  bytes.fiber_first_fiblet = (fibers + 1) * sizeof(uint32_t);
  bytes.fiber_length = fibers * sizeof(float);
  bytes.block = sizeof(shader::FibletDataset);
  bytes.bounds = fiblets * kFibletBoundsBytes;
  return bytes;
}

void checkDatasetFits(const std::string& name, uint64_t fibers, uint64_t fiblets, const DatasetBytes& bytes,
                      const DeviceLimits& limits) {
  // 2^32 - 1 itself is refused too: fiber_first_fiblet's last entry is the
  // fiblet count, and the fiber index must leave room for fibers + 1.
  if (fiblets >= kMaxCount || fibers >= kMaxCount)
    fail(name, std::to_string(fiblets) + " fiblets of " + std::to_string(fibers) +
                   " fibers: the GPU renderer indexes fiblets and fibers with 32 bits (at most " +
                   std::to_string(kMaxCount - 1) + " each); streaming is not implemented yet");
  const uint64_t per_buffer = std::min(limits.max_allocation_bytes, limits.max_buffer_bytes);
  const uint64_t total = bytes.total();
  if (total <= limits.device_local_heap_bytes && bytes.largest() <= per_buffer) return;
  // Name the single buffer when it, not the total, is what does not fit.
  const std::string buffer_note =
      total <= limits.device_local_heap_bytes
          ? std::string(bytes.largest() == bytes.records ? "the fiblet records need" : "one table needs") +
                " one buffer of " + formatBytes(double(bytes.largest())) + "; "
          : std::string();
  const std::string what = formatBytes(double(total)) + " of fiblets and tables do not fit on " + limits.device_name +
                           " (" + buffer_note + "largest allocation " +
                           formatBytes(double(limits.max_allocation_bytes)) + ", largest buffer " +
                           formatBytes(double(limits.max_buffer_bytes)) + ", device-local heap " +
                           formatBytes(double(limits.device_local_heap_bytes)) + "); streaming is not implemented yet";
  fail(name, what);
}

GpuDataset::~GpuDataset() { release(); }

GpuDataset::GpuDataset(GpuDataset&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)),
      records_(std::exchange(other.records_, {})),
      fiblet_fiber_(std::exchange(other.fiblet_fiber_, {})),
      directions_(std::exchange(other.directions_, {})),
      fiber_first_fiblet_(std::exchange(other.fiber_first_fiblet_, {})),
      fiber_length_(std::exchange(other.fiber_length_, {})),
      block_buffer_(std::exchange(other.block_buffer_, {})),
      bounds_(std::exchange(other.bounds_, {})),
      block_(std::exchange(other.block_, {})),
      bounds_ready_(std::exchange(other.bounds_ready_, false)) {}

GpuDataset& GpuDataset::operator=(GpuDataset&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    records_ = std::exchange(other.records_, {});
    fiblet_fiber_ = std::exchange(other.fiblet_fiber_, {});
    directions_ = std::exchange(other.directions_, {});
    fiber_first_fiblet_ = std::exchange(other.fiber_first_fiblet_, {});
    fiber_length_ = std::exchange(other.fiber_length_, {});
    block_buffer_ = std::exchange(other.block_buffer_, {});
    bounds_ = std::exchange(other.bounds_, {});
    block_ = std::exchange(other.block_, {});
    bounds_ready_ = std::exchange(other.bounds_ready_, false);
  }
  return *this;
}

void GpuDataset::release() {
  if (!context_) return;
  for (gpu::Buffer* b :
       {&records_, &fiblet_fiber_, &directions_, &fiber_first_fiblet_, &fiber_length_, &block_buffer_, &bounds_})
    gpu::destroyBuffer(*context_, *b);
  context_ = nullptr;
  block_ = {};
}

uint64_t GpuDataset::bytes() const {
  return records_.size + fiblet_fiber_.size + directions_.size + fiber_first_fiblet_.size + fiber_length_.size +
         block_buffer_.size + bounds_.size;
}

void GpuDataset::computeFibletBounds() {
  if (!context_) return;
  fibscope::computeFibletBounds(*context_, block_buffer_.address, bounds_.address, block_.fiblet_count);
  bounds_ready_ = true;
  useFibletBounds(true);
}

void GpuDataset::recordFibletBoundsOnce(VkCommandBuffer cmd, const FibletBoundsPass& pass) const {
  if (!context_ || bounds_ready_) return;
  // Earlier work of this command buffer (uploads are separate submissions,
  // already complete) needs no barrier: the pass reads records, table and
  // block, which only transfers of finished submissions wrote.
  recordFibletBounds(cmd, *context_, pass, block_buffer_.address, bounds_.address, block_.fiblet_count);
  // The pass (and earlier frames' passes) read the block: done before the
  // update writes it.
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                     VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
  block_.fiblet_bounds = bounds_.address;
  vkCmdUpdateBuffer(cmd, block_buffer_.buffer, offsetof(shader::FibletDataset, fiblet_bounds),
                    sizeof block_.fiblet_bounds, &block_.fiblet_bounds);
  // The spheres (compute) and the block's new address (transfer) before
  // the cull reads them.
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  bounds_ready_ = true;
}

void GpuDataset::useFibletBounds(bool use) {
  if (!context_) return;
  block_.fiblet_bounds = use && bounds_ready_ ? bounds_.address : 0;
  gpu::uploadToBuffer(*context_, block_buffer_, &block_, sizeof block_);
}

// What both upload paths hand to the common part, after the size check.
struct GpuDataset::Source {
  ChunkSource records;  // any range, from several threads at once (uploadRandomAccess)
  FiberTables tables;
  std::span<const float> fiber_length_mm;
  CodecParams params;
};

// Allocates every buffer, then copies; on an exception the caller's
// partly built dataset frees what was allocated.
void GpuDataset::fill(const gpu::VulkanContext& context, const Source& source, const DatasetBytes& bytes,
                      Progress* progress, uint64_t staging_bytes) {
  context_ = &context;
  records_ = gpu::createBuffer(context, bufferSize(bytes.records), gpu::MemoryUse::DeviceLocal);
  fiblet_fiber_ = gpu::createBuffer(context, bufferSize(bytes.fiblet_fiber), gpu::MemoryUse::DeviceLocal);
  directions_ = gpu::createBuffer(context, bufferSize(bytes.directions), gpu::MemoryUse::DeviceLocal);
  fiber_first_fiblet_ = gpu::createBuffer(context, bufferSize(bytes.fiber_first_fiblet), gpu::MemoryUse::DeviceLocal);
  fiber_length_ = gpu::createBuffer(context, bufferSize(bytes.fiber_length), gpu::MemoryUse::DeviceLocal);
  block_buffer_ = gpu::createBuffer(context, bufferSize(bytes.block), gpu::MemoryUse::DeviceLocal);
  bounds_ = gpu::createBuffer(context, bufferSize(bytes.bounds), gpu::MemoryUse::DeviceLocal);

  const CodecParams& params = source.params;
  block_.records = records_.address;
  block_.fiblet_fiber = fiblet_fiber_.address;
  block_.directions = directions_.address;
  block_.fiber_first_fiblet = fiber_first_fiblet_.address;
  block_.fiber_length_mm = fiber_length_.address;
  block_.fiblet_bounds = 0;  // filled when the occlusion cull first needs them
  block_.fiber_count = uint32_t(source.tables.first.size() - 1);
  block_.fiblet_count = uint32_t(source.tables.fiblet_fiber.size());
  block_.record_words = params.recordBytes() / 4;
  block_.points_per_fiblet = params.points_per_fiblet;
  block_.translation_x = params.translation[0];
  block_.translation_y = params.translation[1];
  block_.translation_z = params.translation[2];
  block_.mm_per_unit = float(1.0 / double(params.scale));
  block_.delta = params.delta;
  block_.v_x = params.v[0];
  block_.v_y = params.v[1];
  block_.v_z = params.v[2];
  const FibletDirectionTable directions = buildDirectionTable(params.alpha);
  // The table the shaders read: the 256 directions, then each code's local
  // transform L_c (fibletLocalTransform: the same arithmetic as the
  // decoders, so the same bits) as 12 floats in 3 vec4, so decoding a point
  // costs a table load instead of a frame construction.
  std::vector<shader::vec4> table(directions.begin(), directions.end());
  for (const shader::vec4& d : directions) {
    const shader::FibletTransform l =
        shader::fibletLocalTransform(shader::vec3(d.x, d.y, d.z), shader::vec3(block_.v_x, block_.v_y, block_.v_z),
                                     block_.delta);
    table.push_back({l.c0.x, l.c0.y, l.c0.z, l.c1.x});
    table.push_back({l.c1.y, l.c1.z, l.c2.x, l.c2.y});
    table.push_back({l.c2.z, l.t.x, l.t.y, l.t.z});
  }

  if (progress) progress->setTotal(double(bytes.total() - bytes.bounds));  // the bounds are computed later
  // The staging buffer only where a buffer cannot be written directly
  // (discrete GPUs); CPU and integrated devices take the bytes in place.
  gpu::Buffer staging;
  const auto stage = [&]() -> const gpu::Buffer& {
    if (staging.buffer == VK_NULL_HANDLE)
      staging = gpu::createBuffer(context, std::clamp<uint64_t>(bytes.largest(), 4, std::max<uint64_t>(staging_bytes, 4)),
                                  gpu::MemoryUse::Upload);
    return staging;
  };
  try {
    uploadRandomAccess(context, stage, records_, bytes.records, source.records, progress);
    uploadRandomAccess(context, stage, fiblet_fiber_, bytes.fiblet_fiber, bytesOf(source.tables.fiblet_fiber.data()),
                       progress);
    uploadRandomAccess(context, stage, directions_, bytes.directions, bytesOf(table.data()), progress);
    uploadRandomAccess(context, stage, fiber_first_fiblet_, bytes.fiber_first_fiblet,
                       bytesOf(source.tables.first.data()), progress);
    uploadRandomAccess(context, stage, fiber_length_, bytes.fiber_length, bytesOf(source.fiber_length_mm.data()),
                       progress);
    uploadRandomAccess(context, stage, block_buffer_, bytes.block, bytesOf(&block_), progress);
  } catch (...) {
    gpu::destroyBuffer(context, staging);
    throw;
  }
  gpu::destroyBuffer(context, staging);
}

GpuDataset GpuDataset::upload(const gpu::VulkanContext& context, const FblFile& file, Progress* progress,
                              const DeviceLimits* limits, uint64_t staging_bytes) {
  const std::string& name = file.path();
  Source source;
  source.params = codecParamsFromFbl(file.header(), name);
  const uint32_t record_bytes = source.params.recordBytes();

  // Sizes from the section table only: nothing is read or allocated before
  // the size check.
  const auto section = [&](std::string_view section_name, FblDType dtype) -> const FblSection& {
    const FblSection* s = file.find(section_name);
    if (!s) fail(name, "no \"" + std::string(section_name) + "\" section");
    if (s->dtype != dtype || s->components != 1)
      fail(name, "section \"" + std::string(section_name) + "\" is " + fblDTypeName(s->dtype) + " x " +
                     std::to_string(s->components) + ", expected " + fblDTypeName(dtype) + " x 1");
    return *s;
  };
  const FblSection& fiblet_section = section(kFblSectionFiblets, FblDType::kUint32);
  const FblSection& first_section = section(kFblSectionFiberFirstFiblet, FblDType::kUint64);
  const FblSection& length_section = section(kFblSectionFiberLength, FblDType::kFloat32);
  if (fiblet_section.bytes % record_bytes != 0)
    fail(name, "section \"fiblets\" has " + std::to_string(fiblet_section.bytes) + " bytes, not a whole number of " +
                   std::to_string(record_bytes) + "-byte records");
  const uint64_t fiblets = fiblet_section.bytes / record_bytes;
  if (first_section.element_count == 0) fail(name, "section \"fiber_first_fiblet\" is empty, expected fibers + 1");
  const uint64_t fibers = first_section.element_count - 1;
  if (fiblets != file.header().fiblet_count || fibers != file.header().fiber_count)
    fail(name, "the sections hold " + std::to_string(fiblets) + " fiblets of " + std::to_string(fibers) +
                   " fibers, the header says " + std::to_string(file.header().fiblet_count) + " of " +
                   std::to_string(file.header().fiber_count));
  if (length_section.element_count != fibers)
    fail(name, "section \"fiber_length_mm\" has " + std::to_string(length_section.element_count) +
                   " values, expected one per fiber (" + std::to_string(fibers) + ")");
  const DatasetBytes bytes = datasetBytes(fibers, fiblets, record_bytes);
  checkDatasetFits(name, fibers, fiblets, bytes, limits ? *limits : deviceLimits(context));

  source.tables = deriveFiberTables(name, file.array<uint64_t>(first_section), fiblets);
  source.fiber_length_mm = file.array<float>(length_section);
  source.records = bytesOf(file.data(fiblet_section).data());

  GpuDataset dataset;
  dataset.fill(context, source, bytes, progress, staging_bytes);
  return dataset;
}

GpuDataset GpuDataset::upload(const gpu::VulkanContext& context, const EncodedFiblets& fiblets,
                              const CodecParams& params, std::span<const float> fiber_length_mm,
                              const std::string& name, Progress* progress, const DeviceLimits* limits,
                              uint64_t staging_bytes) {
  const EncodedFiblets* const whole = &fiblets;
  return upload(context, std::span<const EncodedFiblets* const>(&whole, 1), params, fiber_length_mm, name, progress,
                limits, staging_bytes);
}

GpuDataset GpuDataset::upload(const gpu::VulkanContext& context, std::span<const EncodedFiblets* const> parts,
                              const CodecParams& params, std::span<const float> fiber_length_mm,
                              const std::string& name, Progress* progress, const DeviceLimits* limits,
                              uint64_t staging_bytes) {
  validateCodecParams(params);
  const uint32_t record_bytes = params.recordBytes();
  uint64_t count = 0, fibers = 0;
  // Where each part's records start in the joined records (parts + 1).
  std::vector<uint64_t> part_begin{0};
  for (const EncodedFiblets* part : parts) {
    if (part->fiblet_base != 0)
      fail(name, "the fiblets start at global index " + std::to_string(part->fiblet_base) +
                     ": only whole tractograms can be uploaded");
    if (part->record_bytes != record_bytes || part->bytes.size() % record_bytes != 0)
      fail(name, std::to_string(part->bytes.size()) + " bytes of " + std::to_string(part->record_bytes) +
                     "-byte records, expected whole " + std::to_string(record_bytes) +
                     "-byte records for N = " + std::to_string(params.points_per_fiblet));
    count += part->fibletCount();
    fibers += part->fiber_first_fiblet.size();
    part_begin.push_back(part_begin.back() + part->bytes.size());
  }
  if (fiber_length_mm.size() != fibers)
    fail(name, std::to_string(fiber_length_mm.size()) + " fiber lengths for " + std::to_string(fibers) + " fibers");
  const DatasetBytes bytes = datasetBytes(fibers, count, record_bytes);
  checkDatasetFits(name, fibers, count, bytes, limits ? *limits : deviceLimits(context));

  Source source;
  source.params = params;
  std::vector<uint32_t> first;
  first.reserve(fibers + 1);
  uint64_t base = 0;
  for (const EncodedFiblets* part : parts) {
    for (uint32_t f : part->fiber_first_fiblet) first.push_back(uint32_t(base + f));  // < 2^32: checked above
    base += part->fibletCount();
  }
  first.push_back(uint32_t(count));
  source.tables = deriveFiberTables(name, std::span<const uint32_t>(first), count);
  source.fiber_length_mm = fiber_length_mm;
  // The joined records, read from the parts.
  source.records = [parts, &part_begin](uint8_t* out, uint64_t offset, uint64_t n) {
    size_t p = size_t(std::upper_bound(part_begin.begin(), part_begin.end(), offset) - part_begin.begin()) - 1;
    while (n > 0) {
      const uint64_t within = offset - part_begin[p];
      const uint64_t take = std::min(n, part_begin[p + 1] - offset);
      std::memcpy(out, parts[p]->bytes.data() + within, size_t(take));
      out += take;
      offset += take;
      n -= take;
      ++p;
    }
  };

  GpuDataset dataset;
  dataset.fill(context, source, bytes, progress, staging_bytes);
  return dataset;
}

}  // namespace fibscope
