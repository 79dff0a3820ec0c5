// Internal to src/svo/gpu: the pieces the octree's GPU build shares
// between its voxelisation and sort (gpu_svo.cpp) and its tree and lists
// (gpu_svo_tree.cpp): the radix sort's pipelines and chunked exclusive
// scan, a buffer owner, and the sorted leaves left on the device.
#pragma once

#include <algorithm>
#include <cstdint>
#include <deque>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"
#include "shared/svo.h"
#include "svo/gpu/gpu_svo.h"

namespace fibscope::svo_gpu {

// The sort's pipelines (and the scan's, which the tree build reuses).
struct RadixPipelines {
  gpu::ComputePipeline histogram, scan, scan_add, scatter;
  explicit RadixPipelines(const gpu::VulkanContext& c) : context(c) {
    try {
      histogram = gpu::createComputePipeline(c, "radix_histogram.comp", sizeof(shader::RadixPush));
      scan = gpu::createComputePipeline(c, "radix_scan.comp", sizeof(shader::RadixScanPush));
      scan_add = gpu::createComputePipeline(c, "radix_scan_add.comp", sizeof(shader::RadixScanPush));
      scatter = gpu::createComputePipeline(c, "radix_scatter.comp", sizeof(shader::RadixPush));
    } catch (...) {
      destroy();
      throw;
    }
  }
  RadixPipelines(const RadixPipelines&) = delete;
  RadixPipelines& operator=(const RadixPipelines&) = delete;
  ~RadixPipelines() { destroy(); }
  void destroy() {
    gpu::destroyComputePipeline(context, scatter);
    gpu::destroyComputePipeline(context, scan_add);
    gpu::destroyComputePipeline(context, scan);
    gpu::destroyComputePipeline(context, histogram);
  }
  const gpu::VulkanContext& context;
};

// Owns buffers made in one function, released in reverse order (a
// buffer released early is a null buffer then).
struct Buffers {
  explicit Buffers(const gpu::VulkanContext& c) : context(c) {}
  Buffers(const Buffers&) = delete;
  Buffers& operator=(const Buffers&) = delete;
  ~Buffers() {
    for (auto it = list.rbegin(); it != list.rend(); ++it) gpu::destroyBuffer(context, *it);
  }
  gpu::Buffer& make(VkDeviceSize bytes, gpu::MemoryUse use) {
    return list.emplace_back(gpu::createBuffer(context, std::max<VkDeviceSize>(bytes, 4), use));
  }
  void release(gpu::Buffer& b) { gpu::destroyBuffer(context, b); }
  const gpu::VulkanContext& context;
  std::deque<gpu::Buffer> list;
};

// Words of scratch recordScan needs for n words: each level's chunk totals.
uint64_t scanScratchWords(uint64_t n);

// The exclusive scan of the n words at `data` in place, the chunks' totals
// at `scratch` (scanScratchWords(n) words).
void recordScan(const gpu::VulkanContext& context, VkCommandBuffer cmd, const RadixPipelines& p, VkDeviceAddress data,
                uint64_t n, VkDeviceAddress scratch);

// The voxelisation's sorted leaves, on the device: codes (sorted, unique)
// and f's bits, `count` of each; the buffers belong to the Buffers the
// voxelisation was given.
struct DeviceLeaves {
  const gpu::Buffer* codes = nullptr;
  const gpu::Buffer* distances = nullptr;
  uint32_t count = 0;
};

// The tree and its decoration lists and level of detail from `leaves`
// (gpu_svo_tree.cpp): the same SvoTree buildSvoTree makes of the same
// leaves. Progress as "building".
SvoTree buildSvoTreeOnDevice(const gpu::VulkanContext& context, const TubeModel& model, const GpuTubes& tubes,
                             const SvoGrid& grid, const DeviceLeaves& leaves, const RadixPipelines& radix,
                             Buffers& buffers, const SvoGpuBuildOptions& options, SvoGpuTreeTimes* times = nullptr);

}  // namespace fibscope::svo_gpu
