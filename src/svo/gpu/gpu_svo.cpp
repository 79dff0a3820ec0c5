#include "svo/gpu/gpu_svo.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/progress.h"
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "render/gpu/frame_stages.h"
#include "shared/svo.h"
#include "svo/gpu/svo_gpu_detail.h"

namespace fibscope {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string megabytes(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f MB", double(bytes) / 1e6);
  return text;
}

using svo_gpu::Buffers;
using svo_gpu::RadixPipelines;

// Words of the sort's counts buffer for `count` keys: the digit-major
// counts, then each level's chunk totals of the scan above them.
uint64_t radixCountsWords(uint64_t count) {
  const uint64_t blocks = (count + shader::kRadixBlock - 1) / shader::kRadixBlock;
  const uint64_t n = blocks * shader::kRadixDigits;
  return n + svo_gpu::scanScratchWords(n) + 1;
}

// Records the sort of `count` pairs in (keys, values), using (keys2,
// values2) and `counts` (radixCountsWords(count) words) as scratch; an even
// number of passes, so the result ends in (keys, values).
void recordRadixSort(const gpu::VulkanContext& context, VkCommandBuffer cmd, const RadixPipelines& p,
                     const gpu::Buffer& keys, const gpu::Buffer& values, const gpu::Buffer& keys2,
                     const gpu::Buffer& values2, const gpu::Buffer& counts, uint32_t count, uint32_t bits) {
  uint32_t passes = (bits + 3) / 4;
  passes += passes % 2;
  const uint32_t blocks = (count + shader::kRadixBlock - 1) / shader::kRadixBlock;
  const gpu::DispatchGrid grid = gpu::dispatchGrid(context, blocks);
  for (uint32_t pass = 0; pass < passes; ++pass) {
    const bool even = pass % 2 == 0;
    shader::RadixPush push{};
    push.keys_in = even ? keys.address : keys2.address;
    push.values_in = even ? values.address : values2.address;
    push.keys_out = even ? keys2.address : keys.address;
    push.values_out = even ? values2.address : values.address;
    push.counts = counts.address;
    push.count = count;
    // A pass past the key's bits (the count made even) sorts by a digit
    // that is 0 everywhere: stable, it changes nothing.
    push.shift = std::min(4 * pass, 28u);
    push.blocks = blocks;
    gpu::recordDispatch(cmd, p.histogram, push, grid.x, grid.y);
    gpu::computeToComputeBarrier(cmd);
    const uint64_t n = uint64_t(blocks) * shader::kRadixDigits;
    svo_gpu::recordScan(context, cmd, p, counts.address, n, counts.address + n * 4);
    gpu::recordDispatch(cmd, p.scatter, push, grid.x, grid.y);
    gpu::computeToComputeBarrier(cmd);
  }
}

// Each slab's segments, as compressed rows: slab k's are
// ids[first[k] .. first[k + 1]), those whose box widened by r + band (and a
// voxel more than the shader's rounding can need) reaches the slab's z
// range. Splatting only these keeps the voxelisation's work at the
// segments times the slabs each spans, not times all slabs, and a slab no
// segment reaches is skipped (it can hold no leaf).
struct SlabLists {
  std::vector<uint64_t> first;  // slabs + 1
  std::vector<uint32_t> ids;
};
SlabLists slabSegmentLists(const TubeModel& model, const SvoGrid& grid, uint32_t slab_depth, uint32_t slabs) {
  const int side = int(grid.side());
  std::vector<std::pair<uint32_t, uint32_t>> span(model.segments.size(), {1, 0});  // slabs [lo, hi]; empty: lo > hi
  SlabLists out;
  out.first.assign(size_t(slabs) + 1, 0);
  for (size_t i = 0; i < model.segments.size(); ++i) {
    glm::vec3 lo, hi;
    float radius = 0.0f;
    svoSegmentBounds(model, model.segments[i], grid.curved, lo, hi, radius);
    const float pad = radius + grid.band() + grid.voxel;
    const int zlo = std::max(0, int(std::floor((lo.z - pad - grid.origin.z) / grid.voxel - 0.5f)));
    const int zhi = std::min(side - 1, int(std::ceil((hi.z + pad - grid.origin.z) / grid.voxel - 0.5f)));
    if (zlo > zhi) continue;
    span[i] = {uint32_t(zlo) / slab_depth, uint32_t(zhi) / slab_depth};
    for (uint32_t k = span[i].first; k <= span[i].second; ++k) ++out.first[k + 1];
  }
  for (uint32_t k = 0; k < slabs; ++k) out.first[k + 1] += out.first[k];
  out.ids.resize(out.first[slabs]);
  std::vector<uint64_t> at(out.first.begin(), out.first.end() - 1);
  for (size_t i = 0; i < span.size(); ++i)
    for (uint32_t k = span[i].first; k <= span[i].second; ++k) out.ids[at[k]++] = uint32_t(i);
  return out;
}

// Segments splatted per submission at most: one submission of a whole
// slab's list can run past the fence timeout on a CPU device.
constexpr uint64_t kVoxelizeBatchSegments = uint64_t(1) << 20;

}  // namespace

namespace svo_gpu {

uint64_t scanScratchWords(uint64_t n) {
  uint64_t words = 0;
  while (n > 1) {
    n = (n + shader::kRadixScanChunk - 1) / shader::kRadixScanChunk;
    words += n;
  }
  return words;
}

void recordScan(const gpu::VulkanContext& context, VkCommandBuffer cmd, const RadixPipelines& p, VkDeviceAddress data,
                uint64_t n, VkDeviceAddress scratch) {
  const uint64_t chunks = (n + shader::kRadixScanChunk - 1) / shader::kRadixScanChunk;
  const gpu::DispatchGrid grid = gpu::dispatchGrid(context, chunks);
  shader::RadixScanPush push{};
  push.data = data;
  push.sums = scratch;
  push.count = uint32_t(n);
  gpu::recordDispatch(cmd, p.scan, push, grid.x, grid.y);
  gpu::computeToComputeBarrier(cmd);
  if (chunks <= 1) return;  // one chunk: scanned whole
  recordScan(context, cmd, p, scratch, chunks, scratch + chunks * 4);
  gpu::recordDispatch(cmd, p.scan_add, push, grid.x, grid.y);
  gpu::computeToComputeBarrier(cmd);
}

}  // namespace svo_gpu

uint64_t svoMemoryLimit(const gpu::VulkanContext& context, const SvoGpuBuildOptions& options) {
  if (options.memory_limit_bytes) return options.memory_limit_bytes;
  const VkPhysicalDeviceMemoryProperties& m = context.memoryProperties();
  uint64_t largest = 0;
  for (uint32_t i = 0; i < m.memoryHeapCount; ++i)
    if (m.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) largest = std::max(largest, m.memoryHeaps[i].size);
  return largest;
}

void gpuRadixSort(const gpu::VulkanContext& context, std::vector<uint32_t>& keys, std::vector<uint32_t>& values,
                  uint32_t bits) {
  if (keys.size() != values.size()) throw Error("radix sort: " + std::to_string(keys.size()) + " keys but " +
                                                std::to_string(values.size()) + " values");
  if (keys.empty()) return;
  const uint32_t count = uint32_t(keys.size());
  const RadixPipelines p(context);
  Buffers b(context);
  const VkDeviceSize bytes = VkDeviceSize(count) * 4;
  gpu::Buffer& k = b.make(bytes, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& v = b.make(bytes, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& k2 = b.make(bytes, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& v2 = b.make(bytes, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& counts = b.make(VkDeviceSize(radixCountsWords(count)) * 4, gpu::MemoryUse::DeviceLocal);
  gpu::uploadToBuffer(context, k, keys.data(), bytes);
  gpu::uploadToBuffer(context, v, values.data(), bytes);
  gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
    gpu::recordBarrier(cmd, gpu::kTransferToCompute);
    recordRadixSort(context, cmd, p, k, v, k2, v2, counts, count, bits);
  });
  gpu::downloadFromBuffer(context, k, keys.data(), bytes);
  gpu::downloadFromBuffer(context, v, values.data(), bytes);
}

gpu::ComputePipeline createSvoVoxelizePipeline(const gpu::VulkanContext& context) {
  return gpu::createComputePipeline(context, "svo_voxelize.comp", sizeof(shader::SvoVoxelizePush),
                                    gpu::WorkgroupSize{shader::kSvoVoxelizeGroupSize});
}

void recordSvoVoxelize(const gpu::VulkanContext& context, VkCommandBuffer cmd, const gpu::ComputePipeline& voxelize,
                       const GpuTubes& tubes, shader::SvoVoxelizePush push) {
  push.nodes = tubes.nodes.address;
  push.segments = tubes.segments.address;
  if (push.list == 0) push.segment_count = tubes.segment_count;
  const gpu::DispatchGrid g = gpu::dispatchGrid(context, push.segment_count);
  gpu::recordDispatch(cmd, voxelize, push, g.x, g.y);
}

namespace {

// The leaves voxelised and sorted, left on the device in buffers of `b`
// (the dense slab released before it returns).
svo_gpu::DeviceLeaves voxelizeToDevice(const gpu::VulkanContext& context, const TubeModel& model,
                                       const GpuTubes& tubes, const SvoGrid& grid, const SvoGpuBuildOptions& options,
                                       SvoGpuBuildStats& st, const RadixPipelines& radix, Buffers& b) {
  const uint64_t side = grid.side();
  const uint32_t slab_depth = svoSlabDepth(grid, options.field_budget_bytes);
  st.slab_depth = slab_depth;
  st.slabs = uint32_t((side + slab_depth - 1) / slab_depth);
  st.need = estimateSvoMemory(model, grid, slab_depth);
  const uint64_t limit = svoMemoryLimit(context, options);
  if (st.need.total() > limit)
    throw Error("svo: the octree of " + std::to_string(model.segments.size()) + " segments at a voxel of " +
                std::to_string(grid.voxel) + " mm needs about " + megabytes(st.need.total()) + " (distance slab " +
                megabytes(st.need.field) + ", leaves " + megabytes(st.need.sort) + ", nodes " +
                megabytes(st.need.nodes) + ", decoration " + megabytes(st.need.decoration) + ", tree build " +
                megabytes(st.need.tree) +
                "), more than the device's " + megabytes(limit) + ": choose a larger voxel");
  if (tubes.segment_count == 0) return {};

  gpu::ComputePipeline voxelize, compact;
  struct Pipes {
    const gpu::VulkanContext& c;
    gpu::ComputePipeline& a;
    gpu::ComputePipeline& b;
    ~Pipes() {
      gpu::destroyComputePipeline(c, b);
      gpu::destroyComputePipeline(c, a);
    }
  } pipes{context, voxelize, compact};
  voxelize = createSvoVoxelizePipeline(context);
  compact = gpu::createComputePipeline(context, "svo_compact.comp", sizeof(shader::SvoCompactPush),
                                       gpu::WorkgroupSize{shader::kSvoCompactGroupSize});

  gpu::Buffer& field = b.make(side * side * slab_depth * 4, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& count_buffer = b.make(4, gpu::MemoryUse::DeviceLocal);
  uint64_t capacity = std::max<uint64_t>(st.need.leaves, 1024);
  uint32_t count = 0;
  auto start = std::chrono::steady_clock::now();
  const SlabLists lists = slabSegmentLists(model, grid, slab_depth, st.slabs);
  gpu::Buffer& list_buffer = b.make(std::max<size_t>(lists.ids.size(), 1) * 4, gpu::MemoryUse::DeviceLocal);
  if (!lists.ids.empty()) gpu::uploadToBuffer(context, list_buffer, lists.ids.data(), lists.ids.size() * 4);
  for (;;) {
    gpu::Buffer& keys = b.make(capacity * 4, gpu::MemoryUse::DeviceLocal);
    gpu::Buffer& values = b.make(capacity * 4, gpu::MemoryUse::DeviceLocal);
    Progress progress("voxelising", double(st.slabs), "slabs", options.progress, options.progress_sink);
    const uint32_t fill_zero = 0;
    gpu::uploadToBuffer(context, count_buffer, &fill_zero, 4);
    for (uint32_t slab = 0; slab < st.slabs; ++slab) {
      if (options.cancel && options.cancel->load()) throw Error("svo: the build was cancelled");
      const uint32_t z0 = slab * slab_depth;
      const uint32_t depth = uint32_t(std::min<uint64_t>(slab_depth, side - z0));
      const uint64_t begin = lists.first[slab], end = lists.first[slab + 1];
      for (uint64_t at = begin; at < end; at += kVoxelizeBatchSegments) {
        const uint64_t batch = std::min(kVoxelizeBatchSegments, end - at);
        gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
          if (at == begin) {
            // The previous slab's reads of the field before it is refilled.
            gpu::recordBarrier(cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, gpu::kStorageReadWrite,
                                     VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT});
            vkCmdFillBuffer(cmd, field.buffer, 0, VK_WHOLE_SIZE, shader::kSvoFar);
            gpu::recordBarrier(cmd, gpu::kTransferToCompute);
          }
          shader::SvoVoxelizePush vp{};
          vp.list = list_buffer.address + at * 4;
          vp.segment_count = uint32_t(batch);
          vp.field = field.address;
          vp.origin_x = grid.origin.x;
          vp.origin_y = grid.origin.y;
          vp.origin_z = grid.origin.z;
          vp.voxel = grid.voxel;
          vp.side = uint32_t(side);
          vp.slab_z0 = z0;
          vp.slab_depth = depth;
          vp.band = grid.band();
          vp.curved = grid.curved ? 1u : 0u;
          recordSvoVoxelize(context, cmd, voxelize, tubes, vp);
          if (at + batch < end) return;  // the slab's compaction after its last batch
          gpu::computeToComputeBarrier(cmd);
          shader::SvoCompactPush cp{};
          cp.field = field.address;
          cp.keys = keys.address;
          cp.values = values.address;
          cp.count = count_buffer.address;
          cp.side = uint32_t(side);
          cp.slab_z0 = z0;
          cp.slab_depth = depth;
          cp.capacity = uint32_t(std::min<uint64_t>(capacity, 0xFFFFFFFFu));
          cp.band = grid.band();
          const uint64_t voxels = side * side * depth;
          const gpu::DispatchGrid cg =
              gpu::dispatchGrid(context, (voxels + shader::kSvoCompactGroupSize - 1) / shader::kSvoCompactGroupSize);
          gpu::recordDispatch(cmd, compact, cp, cg.x, cg.y);
        });
      }
      progress.add(1);
    }
    progress.finish();
    gpu::downloadFromBuffer(context, count_buffer, &count, 4);
    if (count <= capacity) {
      st.voxelize_s = secondsSince(start);
      start = std::chrono::steady_clock::now();
      b.release(field);
      if (count > 0) {
        Progress sorting("sorting", 1, "sorts", options.progress, options.progress_sink);
        gpu::Buffer& keys2 = b.make(VkDeviceSize(count) * 4, gpu::MemoryUse::DeviceLocal);
        gpu::Buffer& values2 = b.make(VkDeviceSize(count) * 4, gpu::MemoryUse::DeviceLocal);
        gpu::Buffer& counts = b.make(VkDeviceSize(radixCountsWords(count)) * 4, gpu::MemoryUse::DeviceLocal);
        gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
          gpu::computeToComputeBarrier(cmd);  // the compaction's writes (earlier submissions)
          recordRadixSort(context, cmd, radix, keys, values, keys2, values2, counts, count, 3 * grid.levels);
        });
        sorting.add(1);
        sorting.finish();
        // The sort's scratch is not needed by the tree build.
        b.release(counts);
        b.release(values2);
        b.release(keys2);
      }
      st.sort_s = secondsSince(start);
      return {&keys, &values, count};
    }
    // The estimate was short: again with the exact count.
    ++st.retries;
    capacity = count;
    b.release(values);
    b.release(keys);
  }
}

// The sorted leaves the voxelisation left on the device, downloaded.
std::vector<SvoLeaf> downloadLeaves(const gpu::VulkanContext& context, const svo_gpu::DeviceLeaves& d) {
  std::vector<SvoLeaf> leaves(d.count);
  if (d.count == 0) return leaves;
  std::vector<uint32_t> k(d.count), v(d.count);
  gpu::downloadFromBuffer(context, *d.codes, k.data(), size_t(d.count) * 4);
  gpu::downloadFromBuffer(context, *d.distances, v.data(), size_t(d.count) * 4);
  for (uint32_t i = 0; i < d.count; ++i) leaves[i] = {k[i], shader::uintBitsToFloat(v[i])};
  return leaves;
}

}  // namespace

std::vector<SvoLeaf> voxelizeSvoLeavesGpu(const gpu::VulkanContext& context, const TubeModel& model,
                                          const GpuTubes& tubes, const SvoGrid& grid,
                                          const SvoGpuBuildOptions& options, SvoGpuBuildStats* stats) {
  SvoGpuBuildStats local;
  SvoGpuBuildStats& st = stats ? *stats : local;
  const RadixPipelines radix(context);
  Buffers b(context);
  const svo_gpu::DeviceLeaves d = voxelizeToDevice(context, model, tubes, grid, options, st, radix, b);
  const auto start = std::chrono::steady_clock::now();
  std::vector<SvoLeaf> leaves = downloadLeaves(context, d);
  st.sort_s += secondsSince(start);
  return leaves;
}

SvoTree buildSvoGpu(const gpu::VulkanContext& context, const TubeModel& model, const GpuTubes& tubes,
                    const SvoGrid& grid, const SvoGpuBuildOptions& options, SvoGpuBuildStats* stats) {
  SvoGpuBuildStats local;
  SvoGpuBuildStats& st = stats ? *stats : local;
  const RadixPipelines radix(context);
  Buffers b(context);
  const svo_gpu::DeviceLeaves d = voxelizeToDevice(context, model, tubes, grid, options, st, radix, b);
  const auto start = std::chrono::steady_clock::now();
  SvoTree tree;
  if (options.tree_on_cpu.value_or(context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU)) {
    // The CPU reference from the same leaves (downloaded).
    const std::vector<SvoLeaf> leaves = downloadLeaves(context, d);
    Progress building("building", 1, "trees", options.progress, options.progress_sink);
    tree = buildSvoTree(model, grid, leaves, &st.cpu_tree_times);
    building.add(1);
    building.finish();
  } else {
    tree = svo_gpu::buildSvoTreeOnDevice(context, model, tubes, grid, d, radix, b, options, &st.tree_times);
  }
  st.tree_s = secondsSince(start);
  return tree;
}

std::string svoBuildSummary(const TubeModel& model, const SvoTree& tree, const SvoGpuBuildStats& stats) {
  char text[512];
  std::snprintf(text, sizeof(text),
                "svo: %zu segments (streamline buffer %.3f MB), voxel %.3f mm, %u^3 grid in %u slabs, %zu leaves (%zu "
                "with more than 4 segments, at most %zu), nodes %.3f MB, decoration %.3f MB, lod %.3f MB; voxelise "
                "%.3f s, sort %.3f s, build %.3f s",
                model.segments.size(), double(model.deviceBytes()) / 1e6, tree.grid.voxel, tree.grid.side(),
                stats.slabs, tree.leaves, tree.leaves_over_4, tree.max_segments_per_leaf,
                double(tree.nodeBytes()) / 1e6, double(tree.decorationBytes()) / 1e6, double(tree.lodBytes()) / 1e6,
                stats.voxelize_s, stats.sort_s, stats.tree_s);
  std::string line = text;
  const SvoGpuTreeTimes& t = stats.tree_times;
  if (t.lists_s() > 0) {
    std::snprintf(text, sizeof(text),
                  " (on the device: lists %.3f s = count %.3f + fill %.3f + sort %.3f, levels and nodes %.3f s, "
                  "download %.3f s; lod on the CPU %.3f s)",
                  t.lists_s(), t.count_s, t.fill_s, t.sort_s, t.levels_s, t.download_s, t.lod_s);
    line += text;
  }
  return line;
}

GpuSvo uploadSvo(const gpu::VulkanContext& context, const SvoTree& tree) {
  GpuSvo svo;
  svo.grid = tree.grid;
  try {
    const size_t nb = std::max<size_t>(tree.nodeBytes(), 8), db = std::max<size_t>(tree.decorationBytes(), 4);
    svo.nodes = gpu::createBuffer(context, nb, gpu::MemoryUse::DeviceLocal);
    svo.decoration = gpu::createBuffer(context, db, gpu::MemoryUse::DeviceLocal);
    svo.lod = gpu::createBuffer(context, std::max<size_t>(tree.lodBytes(), 4), gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context, svo.nodes, tree.nodes.data(), tree.nodeBytes());
    if (!tree.decoration.empty()) gpu::uploadToBuffer(context, svo.decoration, tree.decoration.data(), tree.decorationBytes());
    if (!tree.lod.empty()) gpu::uploadToBuffer(context, svo.lod, tree.lod.data(), tree.lodBytes());
  } catch (...) {
    destroySvo(context, svo);
    throw;
  }
  return svo;
}

void destroySvo(const gpu::VulkanContext& context, GpuSvo& svo) {
  gpu::destroyBuffer(context, svo.lod);
  gpu::destroyBuffer(context, svo.decoration);
  gpu::destroyBuffer(context, svo.nodes);
}

FrameStageList withSvoStage(FrameStageList stages, const GpuSvo* svo, const GpuTubes* tubes,
                            SvoTraceOptions options) {
  using Factory = std::unique_ptr<FrameStage> (*)(const gpu::VulkanContext&);
  auto at = stages.begin();
  for (; at != stages.end(); ++at) {
    const Factory* f = at->target<Factory>();
    if (f && *f == &makeSurfaceMergeStage) break;
  }
  stages.insert(at, svoTraceStage(svo, tubes, options));
  return stages;
}

}  // namespace fibscope
