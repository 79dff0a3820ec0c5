// SVO streamtubes on the device (issue 16): the GPU radix sort, the GPU
// voxelisation (svo_voxelize.comp, svo_compact.comp: slab by slab, so the
// dense distance field never exceeds a budget), the build that uses them
// (leaves from the GPU, the tree and its decoration lists on the GPU too,
// shared/svo_build.h, to buildSvoTree's layout and values), the octree's
// upload and the ray-tracing frame stage (svo_trace.comp).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/progress.h"
#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/frame_stage.h"
#include "shared/svo.h"
#include "svo/svo_build.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {

// Sorts `keys` (only their low `bits` bits, <= 32) with `values` alongside,
// stable, on the device: kRadixDigits-way LSD passes (histogram, scan,
// scatter; shared/svo.h). keys.size() == values.size(). Throws Error when
// memory runs out.
void gpuRadixSort(const gpu::VulkanContext& context, std::vector<uint32_t>& keys, std::vector<uint32_t>& values,
                  uint32_t bits = 32);

// svo_voxelize.comp, and its dispatch over every segment of `tubes` (or,
// where push.list is set, over the push.segment_count segments it lists)
// with `push`'s field, grid, slab and band (the tube addresses, and without
// a list the segment count, filled in here): the octree's voxelisation and the distance field's
// (gpu_distance_field.h) record it alike. The field must hold kSvoFar
// before and be visible to compute writes.
gpu::ComputePipeline createSvoVoxelizePipeline(const gpu::VulkanContext& context);
void recordSvoVoxelize(const gpu::VulkanContext& context, VkCommandBuffer cmd, const gpu::ComputePipeline& voxelize,
                       const GpuTubes& tubes, shader::SvoVoxelizePush push);

struct SvoGpuBuildOptions {
  uint64_t field_budget_bytes = kSvoDefaultFieldBudget;  // the dense slab's size at most (decides the slab depth)
  // 0: the device's largest device-local heap. The build throws before
  // allocating anything when its estimate (estimateSvoMemory) exceeds it.
  uint64_t memory_limit_bytes = 0;
  bool progress = false;  // progress lines on stderr (voxelising, sorting, building)
  Progress::Sink progress_sink;  // the same reports to a progress bar (the viewer's), when set
  // The tree, lists and level of detail by buildSvoTree on the CPU from
  // the downloaded leaves (the reference, and the benchmarks' side by
  // side) instead of on the device. Unset: on the CPU where the device is
  // a CPU (lavapipe runs the device step 4-5x slower than the compiled
  // buildSvoTree: docs/BENCHMARKS.md), on the device elsewhere.
  std::optional<bool> tree_on_cpu;
  // Not null: the build throws Error ("cancelled") at the next slab (or
  // batch of the device tree step's lists) once it
  // holds true (the viewer quitting during a build).
  const std::atomic<bool>* cancel = nullptr;
};

// Wall time of the device's tree step (host clock; each part ends with a
// wait for the device): the decoration lists (the count passes and the
// offsets' scan, the fill passes, the per-leaf sort), the levels and
// nodes, the download of nodes and lists, and the level of detail (on the
// CPU, from the downloaded tree: svoLodFromTree).
struct SvoGpuTreeTimes {
  double count_s = 0, fill_s = 0, sort_s = 0, levels_s = 0, download_s = 0, lod_s = 0;
  double lists_s() const { return count_s + fill_s + sort_s; }
};

struct SvoGpuBuildStats {
  uint32_t slabs = 0;
  uint32_t slab_depth = 0;
  uint32_t retries = 0;  // reruns after the leaf buffer's estimate proved short
  double voxelize_s = 0, sort_s = 0, tree_s = 0;  // wall time (host clock around each step)
  SvoGpuTreeTimes tree_times;   // tree_s's parts on the device
  SvoTreeTimes cpu_tree_times;  // tree_s's parts with tree_on_cpu
  SvoMemoryNeed need;
};

// The memory a build may use: options.memory_limit_bytes, else the
// device's largest device-local heap (what chooseSvoGrid's density
// criterion is given).
uint64_t svoMemoryLimit(const gpu::VulkanContext& context, const SvoGpuBuildOptions& options = {});

// The leaves (|f| < band) of `tubes`' capsules on `grid`, voxelised and
// sorted on the device, in Morton order.
std::vector<SvoLeaf> voxelizeSvoLeavesGpu(const gpu::VulkanContext& context, const TubeModel& model,
                                          const GpuTubes& tubes, const SvoGrid& grid,
                                          const SvoGpuBuildOptions& options = {}, SvoGpuBuildStats* stats = nullptr);

// voxelizeSvoLeavesGpu, then the tree, its decoration lists (from the
// sorted leaves left on the device) and its nodes built on the device
// (shared/svo_build.h) and downloaded, the level of detail on the CPU
// from them: the SvoTree buildSvoTree makes of the same leaves (or
// buildSvoTree itself where options.tree_on_cpu). Throws Error naming the
// size needed when the estimate exceeds the memory limit, or when the
// decoration exceeds 2^30 words.
SvoTree buildSvoGpu(const gpu::VulkanContext& context, const TubeModel& model, const GpuTubes& tubes,
                    const SvoGrid& grid, const SvoGpuBuildOptions& options = {}, SvoGpuBuildStats* stats = nullptr);

// The device's tree step alone from `leaves` (sorted by code, codes
// unique), uploaded: the tree, lists and level of detail buildSvoGpu makes
// after its voxelisation, for tests and for timing it beside buildSvoTree
// on the same leaves. Throws Error as buildSvoTree does.
SvoTree buildSvoTreeGpu(const gpu::VulkanContext& context, const TubeModel& model, const GpuTubes& tubes,
                        const SvoGrid& grid, const std::vector<SvoLeaf>& leaves,
                        const SvoGpuBuildOptions& options = {}, SvoGpuTreeTimes* times = nullptr);

// One line for the command line: segments, streamline buffer, grid,
// leaves (and those over 4 segments), nodes and decoration MB, the level
// of detail's representatives' MB (beyond the seed's table 1), the times.
std::string svoBuildSummary(const TubeModel& model, const SvoTree& tree, const SvoGpuBuildStats& stats);

struct GpuSvo {
  gpu::Buffer nodes;       // SvoNode[]
  gpu::Buffer decoration;  // uint[]
  gpu::Buffer lod;         // uint per internal node (SvoTree::lod)
  SvoGrid grid;
};
GpuSvo uploadSvo(const gpu::VulkanContext& context, const SvoTree& tree);
void destroySvo(const gpu::VulkanContext& context, GpuSvo& svo);

// The trace's own options, beside the octree's (its grid, straight or
// curved).
struct SvoTraceOptions {
  // Level of detail (shared/svo.h SvoTracePush::lod_px, the error bound
  // there): an internal node smaller than this many pixels is taken as hit
  // by its representative segment. 0: off (the exact walk, bit for bit).
  float lod_px = 0.0f;
  // Not null: uint[2] (device address of a buffer the caller zeroes) that
  // each frame adds the walk's node visits and segment tests to.
  VkDeviceAddress stats = 0;
  // Not null: read at every frame instead of lod_px (the viewer's panel).
  const float* live_lod_px = nullptr;
};

// Surfaces: "svo trace", the octree's straight tubes into the surface
// target (svo_trace.comp). `svo` and `tubes` (the segments the tree's lists
// index) are read every frame and must outlive the renderer.
FrameStageFactory svoTraceStage(const GpuSvo* svo, const GpuTubes* tubes, SvoTraceOptions options = {});
// `stages` with the SVO stage inserted before the surface merge.
FrameStageList withSvoStage(FrameStageList stages, const GpuSvo* svo, const GpuTubes* tubes,
                            SvoTraceOptions options = {});

}  // namespace fibscope
