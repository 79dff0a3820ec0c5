#include "select/gpu/gpu_fiber_filter.h"

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "select/packed_region.h"
#include "shared/fiber_filter.h"

namespace fibscope {

// What one update uploads: the regions in the passes' order (includes,
// excludes, then ordered includes) and the push fields every pass shares.
struct GpuFiberFilter::Packed {
  std::vector<shader::FilterRegion> regions;
  shader::FilterPassPush push{};
};

namespace {

constexpr gpu::WorkgroupSize kGroup{shader::kFilterGroupSize};

uint64_t selectionWords(uint64_t bits) { return (bits + 31) / 32; }

uint64_t groupsFor(uint64_t items) { return (items + shader::kFilterGroupSize - 1) / shader::kFilterGroupSize; }

// Makes `buffer` hold at least `bytes` (contents not kept).
void ensureBuffer(const gpu::VulkanContext& context, gpu::Buffer& buffer, VkDeviceSize bytes, gpu::MemoryUse use) {
  bytes = std::max<VkDeviceSize>(bytes, 16);
  if (buffer.buffer != VK_NULL_HANDLE && buffer.size >= bytes) return;
  gpu::destroyBuffer(context, buffer);
  buffer = gpu::createBuffer(context, bytes, use);
}

void setBit(uint32_t& lo, uint32_t& hi, uint32_t bit) { (bit < 32 ? lo : hi) |= 1u << (bit % 32); }

// The criteria and the sources, as text: update() does nothing when they
// are those of the last time.
// The values as a key: their count and a 64-bit hash of their bits (the
// vectors' addresses would not do: a freed vector's address comes back
// with other values). Hashing is a few ms for ten million fibers, paid
// only by an update() call, which callers make when something changed.
std::string scalarKey(std::span<const std::vector<float>> scalars) {
  std::string key;
  for (const std::vector<float>& v : scalars) {
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (const float f : v) {
      uint32_t bits;
      std::memcpy(&bits, &f, 4);
      h = (h ^ bits) * 0x100000001B3ull;
    }
    char buf[48];
    std::snprintf(buf, sizeof buf, "%zu:%016llx;", v.size(), static_cast<unsigned long long>(h));
    key += buf;
  }
  return key;
}

std::string signatureOf(const FiberFilter& filter, const std::string& sources,
                        std::span<const std::vector<float>> scalars) {
  const FilterCriteria& c = filter.criteria();
  std::string s = sources + "|scalars " + scalarKey(scalars);
  for (size_t i = 0; i < c.scalar_ranges.size(); ++i) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a,%a;", double(filter.scalarMin(i)), double(filter.scalarMax(i)));
    s += buf;
  }
  for (const auto* list : {&c.include, &c.exclude, &c.include_ordered}) {
    s += '|';
    for (const Region& r : *list) s += regionSpec(r) + ';';
  }
  if (c.distance_zone) s += "|zone " + regionSpec(*c.distance_zone);
  char buf[96];
  std::snprintf(buf, sizeof buf, "|%d|%a|%a|%a", int(c.ends_only), double(filter.minLength()), double(filter.maxLength()),
                double(filter.maxZoneDistance2()));
  return s + buf;
}

}  // namespace

GpuFiberFilter::GpuFiberFilter(const gpu::VulkanContext& context) : context_(context) {
  try {
    const uint32_t push = sizeof(shader::FilterPassPush);
    fiblet_hits_ = gpu::createComputePipeline(context, "filter_fiblet_hits.comp", push, kGroup);
    fiblet_ordered_ = gpu::createComputePipeline(context, "filter_fiblet_ordered.comp", push, kGroup);
    raw_hits_ = gpu::createComputePipeline(context, "filter_raw_hits.comp", push, kGroup);
    raw_points_ = gpu::createComputePipeline(context, "filter_raw_points.comp", push, kGroup);
    combine_ = gpu::createComputePipeline(context, "filter_combine.comp", push, kGroup);
    timer_ = gpu::createGpuTimer(context, 1);
  } catch (...) {
    release();
    throw;
  }
}

GpuFiberFilter::~GpuFiberFilter() { release(); }

void GpuFiberFilter::release() {
  vkDeviceWaitIdle(context_.device());
  for (gpu::ComputePipeline* p : {&fiblet_hits_, &fiblet_ordered_, &raw_hits_, &raw_points_, &combine_})
    gpu::destroyComputePipeline(context_, *p);
  gpu::destroyGpuTimer(context_, timer_);
  for (gpu::Buffer* b : {&regions_, &hits_, &kept_, &point_bits_, &zone_d2_, &zone_mm_, &scalar_values_, &scalar_ranges_})
    gpu::destroyBuffer(context_, *b);
  scalar_key_.clear();
  for (gpu::Buffer& b : masks_) gpu::destroyBuffer(context_, b);
  masks_.clear();
}

void GpuFiberFilter::clear() {
  active_ = false;
  raw_ = false;
  signature_.clear();
  kept_count_ = fibers_;
  last_ms_ = 0;
}

void GpuFiberFilter::prepare(const FiberFilter& filter, uint32_t scene_fibers, uint64_t points,
                             std::span<const std::vector<float>> scalars, Packed& packed) {
  const FilterCriteria& c = filter.criteria();
  if (scalars.size() != c.scalar_ranges.size())
    throw Error("filter: " + std::to_string(c.scalar_ranges.size()) + " scalar ranges but values for " +
                std::to_string(scalars.size()));
  for (size_t r = 0; r < scalars.size(); ++r)
    if (scalars[r].size() != scene_fibers)
      throw Error("filter: " + std::to_string(scalars[r].size()) + " values of " + scalarRangeArray(c.scalar_ranges[r]) +
                  " for " + std::to_string(scene_fibers) + " fibers");
  if (c.include.size() + c.exclude.size() > shader::kFilterMaxHitRegions)
    throw Error("filter: the GPU filter takes at most " + std::to_string(shader::kFilterMaxHitRegions) +
                " include and exclude regions together");
  if (c.include_ordered.size() > shader::kFilterMaxOrderedRegions)
    throw Error("filter: the GPU filter takes at most " + std::to_string(shader::kFilterMaxOrderedRegions) +
                " ordered include regions");
  shader::FilterPassPush& push = packed.push;
  for (gpu::Buffer& b : masks_) gpu::destroyBuffer(context_, b);
  masks_.clear();
  // A mask's voxel bits go to a buffer of their own (kept until the next update).
  auto pack = [&](const Region& region) {
    shader::FilterRegion r = packRegion(region);
    if (const auto* m = std::get_if<MaskRegion>(&region)) {
      const std::vector<uint32_t>& bits = m->mask->bits;
      masks_.push_back(gpu::createBuffer(context_, std::max<size_t>(bits.size(), 1) * 4, gpu::MemoryUse::DeviceLocal));
      gpu::uploadToBuffer(context_, masks_.back(), bits.data(), bits.size() * 4);
      r.mask = masks_.back().address;
    }
    packed.regions.push_back(r);
  };
  for (const Region& r : c.include) {
    setBit(push.include_lo, push.include_hi, uint32_t(packed.regions.size()));
    pack(r);
  }
  for (const Region& r : c.exclude) {
    setBit(push.exclude_lo, push.exclude_hi, uint32_t(packed.regions.size()));
    pack(r);
  }
  push.hit_regions = uint32_t(packed.regions.size());
  for (const Region& r : c.include_ordered) pack(r);
  push.ordered_regions = uint32_t(c.include_ordered.size());
  has_zone_ = filter.zone() != nullptr;
  if (has_zone_) {
    packed.regions.push_back(*filter.zone());
    push.has_zone = 1;
    push.max_d2 = filter.maxZoneDistance2();
    push.zone_radius = filter.zone()->kind == shader::kFilterSphere ? filter.zone()->v[3] : 0.0f;
  }
  push.ends_only = c.ends_only ? 1u : 0u;
  push.min_length = filter.minLength();
  push.max_length = filter.maxLength();

  try {
    ensureBuffer(context_, regions_, packed.regions.size() * sizeof(shader::FilterRegion), gpu::MemoryUse::Upload);
    if (!packed.regions.empty())
      std::memcpy(regions_.mapped, packed.regions.data(), packed.regions.size() * sizeof(shader::FilterRegion));
    ensureBuffer(context_, hits_, uint64_t(scene_fibers) * 16, gpu::MemoryUse::DeviceLocal);
    ensureBuffer(context_, kept_, selectionWords(scene_fibers) * 4, gpu::MemoryUse::DeviceLocal);
    if (points > 0) ensureBuffer(context_, point_bits_, selectionWords(points) * 4, gpu::MemoryUse::DeviceLocal);
    if (has_zone_) {
      ensureBuffer(context_, zone_d2_, uint64_t(scene_fibers) * 4, gpu::MemoryUse::DeviceLocal);
      ensureBuffer(context_, zone_mm_, uint64_t(scene_fibers) * 4, gpu::MemoryUse::DeviceLocal);
    }
    if (!scalars.empty()) {
      // The values go up only when they changed: a ROI dragged in the
      // viewer changes the criteria, not the file's values.
      const std::string key = scalarKey(scalars);
      const uint64_t per_range = uint64_t(scene_fibers) * 4;
      if (key != scalar_key_ || scalar_values_.size < per_range * scalars.size()) {
        scalar_key_.clear();
        ensureBuffer(context_, scalar_values_, per_range * scalars.size(), gpu::MemoryUse::DeviceLocal);
        for (size_t r = 0; r < scalars.size(); ++r)
          gpu::uploadToBuffer(context_, scalar_values_, scalars[r].data(), per_range, per_range * r);
        scalar_key_ = key;
      }
      shader::FilterScalarRanges block{};
      block.count = uint32_t(scalars.size());
      for (size_t r = 0; r < scalars.size(); ++r)
        block.ranges[r] = {scalar_values_.address + per_range * r, filter.scalarMin(r), filter.scalarMax(r)};
      ensureBuffer(context_, scalar_ranges_, sizeof block, gpu::MemoryUse::Upload);
      std::memcpy(scalar_ranges_.mapped, &block, sizeof block);
      push.scalar_ranges = scalar_ranges_.address;
    }
  } catch (...) {
    clear();
    throw;
  }
  push.regions = regions_.address;
  push.hits = hits_.address;
  push.kept = kept_.address;
  push.point_bits = point_bits_.address;
  push.zone_d2 = zone_d2_.address;
  push.zone_mm = zone_mm_.address;
}


bool GpuFiberFilter::update(const FiberFilter& filter, std::span<const FilterFibletSource> sources,
                            uint32_t scene_fibers, std::span<const std::vector<float>> scalars) {
  std::string where = "fiblets:" + std::to_string(scene_fibers);
  for (const FilterFibletSource& src : sources) {
    if (uint64_t(src.fiber_base) + src.fibers > scene_fibers)
      throw Error("filter: a dataset's fibers lie outside the scene's " + std::to_string(scene_fibers));
    char buf[80];
    std::snprintf(buf, sizeof buf, ":%llx,%u,%llx", static_cast<unsigned long long>(src.block), src.fiber_base,
                  static_cast<unsigned long long>(src.lengths));
    where += buf;
  }
  const std::string signature = signatureOf(filter, where, scalars);
  if (active_ && !raw_ && signature == signature_) {
    last_ms_ = 0;
    return false;
  }
  fibers_ = scene_fibers;
  if ((filter.criteria().empty() && !filter.zone()) || scene_fibers == 0) {
    clear();
    signature_ = signature;
    return true;
  }
  Packed packed;
  prepare(filter, scene_fibers, 0, scalars, packed);
  gpu::submitOnce(context_, [&](VkCommandBuffer cmd) {
    gpu::resetGpuTimer(cmd, timer_);
    vkCmdFillBuffer(cmd, hits_.buffer, 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(cmd, kept_.buffer, 0, VK_WHOLE_SIZE, 0);
    if (has_zone_) vkCmdFillBuffer(cmd, zone_d2_.buffer, 0, VK_WHOLE_SIZE, 0x7F800000u);  // +inf
    gpu::recordBarrier(cmd, gpu::kTransferToCompute);
    gpu::PassScope pass(cmd, &timer_, "filter", gpu::kNoBarrier);
    auto dispatch = [&](const gpu::ComputePipeline& pipeline, const FilterFibletSource& src, uint64_t items) {
      shader::FilterPassPush push = packed.push;
      push.source = src.block;
      push.hits = hits_.address + uint64_t(src.fiber_base) * 16;
      push.zone_d2 = zone_d2_.address + uint64_t(src.fiber_base) * 4;
      push.zone_mm = zone_mm_.address + uint64_t(src.fiber_base) * 4;
      push.lengths = src.lengths;
      push.fiber_count = src.fibers;
      push.fiber_base = src.fiber_base;
      if (items == 0) return;
      const gpu::DispatchGrid grid = gpu::dispatchGrid(context_, groupsFor(items));
      gpu::recordDispatch(cmd, pipeline, push, grid.x, grid.y);
    };
    for (const FilterFibletSource& src : sources) dispatch(fiblet_hits_, src, src.fiblets);
    gpu::computeToComputeBarrier(cmd);
    if (packed.push.ordered_regions > 0) {
      for (const FilterFibletSource& src : sources) dispatch(fiblet_ordered_, src, src.fibers);
      gpu::computeToComputeBarrier(cmd);
    }
    for (const FilterFibletSource& src : sources) dispatch(combine_, src, src.fibers);
  });
  raw_ = false;
  finish();
  signature_ = signature;
  return true;
}

bool GpuFiberFilter::update(const FiberFilter& filter, const FilterRawSource& raw,
                            std::span<const std::vector<float>> scalars) {
  const std::string signature =
      signatureOf(filter, "raw:" + std::to_string(raw.block) + "," + std::to_string(raw.lengths), scalars);
  if (active_ && raw_ && signature == signature_) {
    last_ms_ = 0;
    return false;
  }
  fibers_ = raw.streamlines;
  if ((filter.criteria().empty() && !filter.zone()) || raw.streamlines == 0) {
    clear();
    signature_ = signature;
    return true;
  }
  Packed packed;
  prepare(filter, raw.streamlines, std::max<uint64_t>(raw.points, 1), scalars, packed);
  packed.push.source = raw.block;
  packed.push.lengths = raw.lengths;
  packed.push.fiber_count = raw.streamlines;
  packed.push.fiber_base = 0;
  const gpu::DispatchGrid grid = gpu::dispatchGrid(context_, groupsFor(raw.streamlines));
  gpu::submitOnce(context_, [&](VkCommandBuffer cmd) {
    gpu::resetGpuTimer(cmd, timer_);
    vkCmdFillBuffer(cmd, kept_.buffer, 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(cmd, point_bits_.buffer, 0, VK_WHOLE_SIZE, 0);
    gpu::recordBarrier(cmd, gpu::kTransferToCompute);
    gpu::PassScope pass(cmd, &timer_, "filter", gpu::kNoBarrier);
    gpu::recordDispatch(cmd, raw_hits_, packed.push, grid.x, grid.y);
    gpu::computeToComputeBarrier(cmd);
    gpu::recordDispatch(cmd, combine_, packed.push, grid.x, grid.y);
    gpu::computeToComputeBarrier(cmd);
    gpu::recordDispatch(cmd, raw_points_, packed.push, grid.x, grid.y);
  });
  raw_ = true;
  finish();
  signature_ = signature;
  return true;
}

void GpuFiberFilter::finish() {
  active_ = true;
  const std::vector<gpu::PassTime> times = gpu::readGpuTimer(context_, timer_);
  last_ms_ = times.empty() ? 0 : times.front().ms;
  kept_count_ = 0;
  for (uint32_t w : keptWords()) kept_count_ += uint64_t(std::popcount(w));
}

std::vector<float> GpuFiberFilter::zoneDistanceValues() const {
  if (!active_ || !has_zone_) return {};
  std::vector<float> values(fibers_);
  gpu::downloadFromBuffer(context_, zone_mm_, values.data(), values.size() * sizeof(float));
  return values;
}

std::vector<uint32_t> GpuFiberFilter::keptWords() const {
  if (!active_) return {};
  std::vector<uint32_t> words(selectionWords(fibers_));
  gpu::downloadFromBuffer(context_, kept_, words.data(), words.size() * sizeof(uint32_t));
  return words;
}

std::vector<uint32_t> GpuFiberFilter::keptFibers() const {
  const std::vector<uint32_t> words = keptWords();
  std::vector<uint32_t> out;
  for (uint64_t f = 0; f < fibers_ && f / 32 < words.size(); ++f)
    if (words[f / 32] & (1u << (f % 32))) out.push_back(uint32_t(f));
  return out;
}

}  // namespace fibscope
