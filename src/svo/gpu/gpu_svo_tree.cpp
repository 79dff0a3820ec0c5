// The octree's tree and decoration lists on the device (issue 16 item 2;
// shared/svo_build.h), from the sorted leaves the voxelisation leaves
// there, to buildSvoTree's layout and values: the lists by a count pass,
// an exclusive scan of count + 1 (each list's word offset), a fill pass
// and a per-leaf sort; the levels bottom-up (Baert et al.: parent flags,
// their scan, the parents' codes); then every level's nodes at their
// slots. The nodes and lists are downloaded (the viewer's cache and the
// CLI take an SvoTree); the level of detail is made from them on the CPU
// (svoLodFromTree), the one step left there.
#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/progress.h"
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "shared/svo.h"
#include "shared/svo_build.h"
#include "svo/gpu/svo_gpu_detail.h"

namespace fibscope::svo_gpu {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// Segments per submission of the list passes at most: each walks its whole
// band box (not a slab's part of it, as the voxelisation does), so fewer
// than the voxelisation's 2^20, to stay well inside a CPU device's fence
// timeout.
constexpr uint32_t kListsBatchSegments = 1u << 18;

struct TreePipelines {
  gpu::ComputePipeline lists, list_sort, levels, nodes;
  TreePipelines(const gpu::VulkanContext& c, bool curved) : context(c) {
    try {
      const uint32_t lists_variant[] = {curved ? 1u : 0u};
      lists = gpu::createComputePipeline(c, "svo_lists.comp", sizeof(shader::SvoListsPush),
                                         gpu::WorkgroupSize{shader::kSvoListsGroupSize}, lists_variant);
      const gpu::WorkgroupSize tree_group{shader::kSvoTreeGroupSize};
      list_sort = gpu::createComputePipeline(c, "svo_list_sort.comp", sizeof(shader::SvoListSortPush), tree_group);
      levels = gpu::createComputePipeline(c, "svo_levels.comp", sizeof(shader::SvoLevelPush), tree_group);
      nodes = gpu::createComputePipeline(c, "svo_nodes.comp", sizeof(shader::SvoNodesPush), tree_group);
    } catch (...) {
      destroy();
      throw;
    }
  }
  TreePipelines(const TreePipelines&) = delete;
  TreePipelines& operator=(const TreePipelines&) = delete;
  ~TreePipelines() { destroy(); }
  void destroy() {
    gpu::destroyComputePipeline(context, nodes);
    gpu::destroyComputePipeline(context, levels);
    gpu::destroyComputePipeline(context, list_sort);
    gpu::destroyComputePipeline(context, lists);
  }
  const gpu::VulkanContext& context;
};

gpu::DispatchGrid itemGroups(const gpu::VulkanContext& context, uint64_t items) {
  return gpu::dispatchGrid(context, (items + shader::kSvoTreeGroupSize - 1) / shader::kSvoTreeGroupSize);
}

uint32_t downloadWord(const gpu::VulkanContext& context, const gpu::Buffer& buffer, uint64_t index) {
  uint32_t word = 0;
  gpu::downloadFromBuffer(context, buffer, &word, 4, index * 4);
  return word;
}

// svo_lists.comp over segments [first, first + count) in phase `phase`.
void recordSvoLists(const gpu::VulkanContext& context, VkCommandBuffer cmd, const gpu::ComputePipeline& pipeline,
                    shader::SvoListsPush push, uint32_t first, uint32_t count, uint32_t phase) {
  push.segment_first = first;
  push.segment_count = count;
  push.phase = phase;
  const gpu::DispatchGrid g = gpu::dispatchGrid(context, count);
  gpu::recordDispatch(cmd, pipeline, push, g.x, g.y);
}

void recordSvoListSort(const gpu::VulkanContext& context, VkCommandBuffer cmd, const gpu::ComputePipeline& pipeline,
                       const shader::SvoListSortPush& push) {
  const gpu::DispatchGrid g = itemGroups(context, push.leaf_count);
  gpu::recordDispatch(cmd, pipeline, push, g.x, g.y);
}

// svo_levels.comp over count + 1 invocations (the last writes the scan's
// total word).
void recordSvoLevel(const gpu::VulkanContext& context, VkCommandBuffer cmd, const gpu::ComputePipeline& pipeline,
                    const shader::SvoLevelPush& push) {
  const gpu::DispatchGrid g = itemGroups(context, uint64_t(push.count) + 1);
  gpu::recordDispatch(cmd, pipeline, push, g.x, g.y);
}

void recordSvoNodes(const gpu::VulkanContext& context, VkCommandBuffer cmd, const gpu::ComputePipeline& pipeline,
                    const shader::SvoNodesPush& push) {
  const gpu::DispatchGrid g = itemGroups(context, push.count);
  gpu::recordDispatch(cmd, pipeline, push, g.x, g.y);
}

}  // namespace

SvoTree buildSvoTreeOnDevice(const gpu::VulkanContext& context, const TubeModel& model, const GpuTubes& tubes,
                             const SvoGrid& grid, const DeviceLeaves& leaves, const RadixPipelines& radix,
                             Buffers& b, const SvoGpuBuildOptions& options, SvoGpuTreeTimes* times) {
  SvoGpuTreeTimes local_times;
  SvoGpuTreeTimes& tt = times ? *times : local_times;
  SvoTree tree;
  tree.grid = grid;
  tree.leaves = leaves.count;
  const uint32_t levels = grid.levels;
  if (leaves.count == 0) {
    tree.nodes.push_back({shader::kSvoNodeEmpty, 0.0f});
    return tree;
  }
  const uint32_t n = leaves.count;
  const uint32_t segments = uint32_t(model.segments.size());
  const uint32_t batches = (segments + kListsBatchSegments - 1) / kListsBatchSegments;
  Progress progress("building", double(2 * batches + levels + 2), "steps", options.progress, options.progress_sink);
  const TreePipelines p(context, grid.curved);
  auto start = std::chrono::steady_clock::now();

  // The lists: offsets[leaf] = 1 + its segments' count, scanned (exclusive)
  // into word offsets, offsets[n] the decoration's size.
  gpu::Buffer& offsets = b.make(VkDeviceSize(n + 1) * 4, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& scratch = b.make(VkDeviceSize(scanScratchWords(n + 1) + 1) * 4, gpu::MemoryUse::DeviceLocal);
  shader::SvoListsPush lp{};
  lp.nodes = tubes.nodes.address;
  lp.segments = tubes.segments.address;
  lp.codes = leaves.codes->address;
  lp.offsets = offsets.address;
  lp.origin_x = grid.origin.x;
  lp.origin_y = grid.origin.y;
  lp.origin_z = grid.origin.z;
  lp.voxel = grid.voxel;
  lp.side = grid.side();
  lp.leaf_count = n;
  lp.band = grid.band();
  for (uint32_t batch = 0; batch < batches; ++batch) {
    if (options.cancel && options.cancel->load()) throw Error("svo: the build was cancelled");
    const uint32_t first = batch * kListsBatchSegments;
    gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
      // The sort's writes and the previous batch's counts (earlier
      // submissions) before the reads and atomics here.
      gpu::computeToComputeBarrier(cmd);
      if (batch == 0) {
        vkCmdFillBuffer(cmd, offsets.buffer, 0, VK_WHOLE_SIZE, 1u);
        gpu::recordBarrier(cmd, gpu::kTransferToCompute);
      }
      recordSvoLists(context, cmd, p.lists, lp, first, std::min(kListsBatchSegments, segments - first), 0);
    });
    progress.add(1);
  }
  gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
    gpu::computeToComputeBarrier(cmd);
    recordScan(context, cmd, radix, offsets.address, uint64_t(n) + 1, scratch.address);
  });
  const uint32_t words = downloadWord(context, offsets, n);
  tt.count_s = secondsSince(start);
  start = std::chrono::steady_clock::now();
  if (words > shader::kSvoNodeIndexMask)
    throw Error("svo: the decoration holds " + std::to_string(words) +
                " words, more than the 2^30 a leaf reference reaches");
  b.release(scratch);
  gpu::Buffer& decoration = b.make(VkDeviceSize(words) * 4, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& cursor = b.make(VkDeviceSize(n) * 4, gpu::MemoryUse::DeviceLocal);
  lp.cursor = cursor.address;
  lp.decoration = decoration.address;
  for (uint32_t batch = 0; batch < batches; ++batch) {
    if (options.cancel && options.cancel->load()) throw Error("svo: the build was cancelled");
    const uint32_t first = batch * kListsBatchSegments;
    gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
      gpu::computeToComputeBarrier(cmd);  // the scan's offsets, the previous batch's cursors
      if (batch == 0) {
        vkCmdFillBuffer(cmd, cursor.buffer, 0, VK_WHOLE_SIZE, 0u);
        gpu::recordBarrier(cmd, gpu::kTransferToCompute);
      }
      recordSvoLists(context, cmd, p.lists, lp, first, std::min(kListsBatchSegments, segments - first), 1);
    });
    progress.add(1);
  }
  b.release(cursor);
  tt.fill_s = secondsSince(start);
  start = std::chrono::steady_clock::now();
  gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
    gpu::computeToComputeBarrier(cmd);
    shader::SvoListSortPush sp{};
    sp.offsets = offsets.address;
    sp.decoration = decoration.address;
    sp.leaf_count = n;
    recordSvoListSort(context, cmd, p.list_sort, sp);
  });
  tt.sort_s = secondsSince(start);
  start = std::chrono::steady_clock::now();

  // Levels bottom-up: count[l] nodes of level l, their slots in level l -
  // 1's blocks (slots[l], l >= 1), the codes of level l - 1 compacted.
  std::vector<uint32_t> count(levels + 1, 0);
  std::vector<gpu::Buffer*> slots(levels + 1, nullptr);
  count[levels] = n;
  const gpu::Buffer* codes = leaves.codes;
  gpu::Buffer* owned_codes = nullptr;  // level lvl's codes when made here
  for (uint32_t lvl = levels; lvl > 0; --lvl) {
    gpu::Buffer& ranks = b.make(VkDeviceSize(count[lvl] + 1) * 4, gpu::MemoryUse::DeviceLocal);
    gpu::Buffer& level_scratch =
        b.make(VkDeviceSize(scanScratchWords(uint64_t(count[lvl]) + 1) + 1) * 4, gpu::MemoryUse::DeviceLocal);
    gpu::Buffer& parents = b.make(VkDeviceSize(count[lvl]) * 4, gpu::MemoryUse::DeviceLocal);  // at most as many
    gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
      gpu::computeToComputeBarrier(cmd);
      shader::SvoLevelPush vp{};
      vp.codes = codes->address;
      vp.ranks = ranks.address;
      vp.parents = parents.address;
      vp.count = count[lvl];
      vp.phase = 0;
      recordSvoLevel(context, cmd, p.levels, vp);
      gpu::computeToComputeBarrier(cmd);
      recordScan(context, cmd, radix, ranks.address, uint64_t(count[lvl]) + 1, level_scratch.address);
      vp.phase = 1;
      recordSvoLevel(context, cmd, p.levels, vp);
    });
    count[lvl - 1] = downloadWord(context, ranks, count[lvl]);
    slots[lvl] = &ranks;
    b.release(level_scratch);
    if (owned_codes) b.release(*owned_codes);
    owned_codes = &parents;
    codes = &parents;
    progress.add(1);
  }
  if (count[0] != 1) throw Error("svo: the tree's levels end in " + std::to_string(count[0]) + " roots, not one");
  if (owned_codes) b.release(*owned_codes);
  // Layout: node 0 the root; level l's blocks from base[l], one block of 8
  // per node of level l - 1, in code order (buildSvoTree's).
  std::vector<uint64_t> base(levels + 2, 0);
  base[1] = 1;
  for (uint32_t lvl = 1; lvl <= levels; ++lvl) base[lvl + 1] = base[lvl] + 8 * uint64_t(count[lvl - 1]);
  if (base[levels + 1] > shader::kSvoNodeIndexMask)
    throw Error("svo: the tree holds " + std::to_string(base[levels + 1]) + " nodes, more than the 2^30 a node "
                "reference reaches");
  const uint64_t node_count = base[levels + 1];
  gpu::Buffer& nodes = b.make(VkDeviceSize(node_count) * sizeof(shader::SvoNode), gpu::MemoryUse::DeviceLocal);
  gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, nodes.buffer, 0, VK_WHOLE_SIZE, shader::kSvoNodeEmpty);  // and distance 0.0f
    gpu::recordBarrier(cmd, gpu::kTransferToCompute);
    gpu::computeToComputeBarrier(cmd);  // the levels' writes (earlier submissions)
    for (uint32_t lvl = 0; lvl <= levels; ++lvl) {
      shader::SvoNodesPush np{};
      np.nodes = nodes.address;
      np.slots = lvl > 0 ? slots[lvl]->address : 0;
      np.count = count[lvl];
      np.base = uint32_t(base[lvl]);
      if (lvl < levels) {
        np.child_base = uint32_t(base[lvl + 1]);
      } else {
        np.leaf = 1;
        np.offsets = offsets.address;
        np.distances = leaves.distances->address;
      }
      recordSvoNodes(context, cmd, p.nodes, np);
    }
  });
  progress.add(1);
  tt.levels_s = secondsSince(start);
  start = std::chrono::steady_clock::now();

  tree.nodes.resize(node_count);
  tree.decoration.resize(words);
  gpu::downloadFromBuffer(context, nodes, tree.nodes.data(), tree.nodeBytes());
  gpu::downloadFromBuffer(context, decoration, tree.decoration.data(), tree.decorationBytes());
  tt.download_s = secondsSince(start);
  start = std::chrono::steady_clock::now();
  svoCountListStats(tree);
  tree.lod = svoLodFromTree(tree.nodes, tree.decoration, levels);
  tt.lod_s = secondsSince(start);
  progress.add(1);
  progress.finish();
  return tree;
}

}  // namespace fibscope::svo_gpu

namespace fibscope {

SvoTree buildSvoTreeGpu(const gpu::VulkanContext& context, const TubeModel& model, const GpuTubes& tubes,
                        const SvoGrid& grid, const std::vector<SvoLeaf>& leaves, const SvoGpuBuildOptions& options,
                        SvoGpuTreeTimes* times) {
  svo_gpu::Buffers b(context);
  const svo_gpu::RadixPipelines radix(context);
  const uint32_t n = uint32_t(leaves.size());
  gpu::Buffer& codes = b.make(VkDeviceSize(n) * 4, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& distances = b.make(VkDeviceSize(n) * 4, gpu::MemoryUse::DeviceLocal);
  if (n > 0) {
    std::vector<uint32_t> k(n), v(n);
    for (uint32_t i = 0; i < n; ++i) {
      k[i] = leaves[i].code;
      v[i] = shader::floatBitsToUint(leaves[i].distance);
    }
    gpu::uploadToBuffer(context, codes, k.data(), size_t(n) * 4);
    gpu::uploadToBuffer(context, distances, v.data(), size_t(n) * 4);
  }
  return svo_gpu::buildSvoTreeOnDevice(context, model, tubes, grid, {&codes, &distances, n}, radix, b, options,
                                       times);
}

}  // namespace fibscope
