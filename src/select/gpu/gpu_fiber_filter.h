// The fiber filter on the GPU (DESIGN.md section 2, "selection state"):
// the kept bit of every fiber of a scene under a FiberFilter's criteria,
// computed by the passes of shared/fiber_filter.h, for the cull pass to
// skip the fiblets of dropped fibers before decoding them and for the
// baselines to skip their segments. One set of semantics with
// `fibscope filter` (select/fiber_filter.h): the GPU tests the same
// vertices with the same float arithmetic (select/packed_region.h).
//
// Which vertices: a fiblet dataset's decoded points (the serial decode,
// bit for bit the CPU decoder's), a raw tractogram's float vertices (the
// file's own). Lengths: the caller's per-fiber buffer (the dataset's
// fiber_length_mm, the lengths uploaded with a raw tractogram), with
// tckedit's margin from the filter. Scalar ranges: the caller's per-fiber
// values (the file's per-streamline arrays, one float per scene fiber and
// range), uploaded when they change and tested in the combine pass with
// the CPU's float bounds (FiberFilter::scalarMin / scalarMax).
//
// The passes run only when update() sees other criteria or other sources
// than the last time, in one submission of their own between frames.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"
#include "select/fiber_filter.h"

namespace fibscope {

// One fiblet dataset of a scene (render/gpu/scene_table.h's entries).
struct FilterFibletSource {
  VkDeviceAddress block = 0;  // its FibletDataset block
  uint32_t fiblets = 0, fibers = 0;
  uint32_t fiber_base = 0;      // the scene-global id of its fiber 0
  VkDeviceAddress lengths = 0;  // float per fiber (mm)
};

// A raw tractogram (the baselines' input, render/gpu/raw_tractogram.h).
struct FilterRawSource {
  VkDeviceAddress block = 0;  // its RawTractogram block
  uint32_t streamlines = 0;
  uint64_t points = 0;
  VkDeviceAddress lengths = 0;  // float per streamline (mm)
};

class GpuFiberFilter {
 public:
  // Makes the passes' pipelines (throws Error when they cannot be made).
  explicit GpuFiberFilter(const gpu::VulkanContext& context);
  ~GpuFiberFilter();
  GpuFiberFilter(const GpuFiberFilter&) = delete;
  GpuFiberFilter& operator=(const GpuFiberFilter&) = delete;

  // The kept bits of a scene of `scene_fibers` fibers made of `sources`
  // (their fiber ranges inside it), or of a raw tractogram (its
  // streamlines are the scene's fibers; keptPointBits then holds a bit per
  // point). An empty filter keeps everything (keptBits() is then 0).
  // Submits and waits; returns false without GPU work when the criteria
  // and sources are those of the last update. Throws Error for more than
  // kFilterMaxHitRegions include and exclude regions together or
  // kFilterMaxOrderedRegions ordered ones, or when memory runs out (the
  // filter is then empty).
  //
  // `scalars`: with scalar ranges, scalars[r] holds range r's value for
  // every scene fiber (raw: every streamline), in the criteria's order.
  // Values are uploaded again only when they differ from the last
  // update's (compared by a hash of their bits). Throws
  // Error when there are not as many vectors as ranges or a vector's size
  // is not the fiber count.
  bool update(const FiberFilter& filter, std::span<const FilterFibletSource> sources, uint32_t scene_fibers,
              std::span<const std::vector<float>> scalars = {});
  bool update(const FiberFilter& filter, const FilterRawSource& raw, std::span<const std::vector<float>> scalars = {});
  // Keeps everything again.
  void clear();

  // uint words over the scene's fibers (bit f % 32 of word f / 32: fiber f
  // kept), or 0 when everything is kept (no criteria).
  VkDeviceAddress keptBits() const { return active_ ? kept_.address : 0; }
  // Raw sources: uint words, a bit per point (its streamline's kept bit);
  // 0 otherwise or when everything is kept.
  VkDeviceAddress keptPointBits() const { return active_ && raw_ ? point_bits_.address : 0; }
  // Fibers kept by the last update (all of them with no criteria).
  uint64_t keptCount() const { return kept_count_; }
  uint32_t fiberCount() const { return fibers_; }
  // The kept words of the last update (downloaded), or empty with no criteria.
  std::vector<uint32_t> keptWords() const;
  // The kept fibers' ids in order (from keptWords), or empty with no criteria.
  std::vector<uint32_t> keptFibers() const;
  // With a distance zone (FilterCriteria::distance_zone): each fiber's
  // smallest distance to it, mm (float per scene fiber: a ColorMode::Scalar
  // source); 0 otherwise.
  VkDeviceAddress zoneDistances() const { return active_ && has_zone_ ? zone_mm_.address : 0; }
  std::vector<float> zoneDistanceValues() const;  // downloaded; empty without a zone
  // GPU time of the last update's passes (ms), 0 when it did no work.
  double lastGpuMilliseconds() const { return last_ms_; }
  // The next update() runs its passes even for the same criteria and
  // sources (what a changed criterion costs, for benchmarks).
  void invalidate() { signature_.clear(); }

 private:
  struct Packed;
  void release();
  void prepare(const FiberFilter& filter, uint32_t scene_fibers, uint64_t points,
               std::span<const std::vector<float>> scalars, Packed& packed);
  void finish();

  const gpu::VulkanContext& context_;
  gpu::ComputePipeline fiblet_hits_, fiblet_ordered_, raw_hits_, raw_points_, combine_;
  gpu::GpuTimer timer_;
  gpu::Buffer regions_, hits_, kept_, point_bits_, zone_d2_, zone_mm_;
  gpu::Buffer scalar_values_, scalar_ranges_;  // a float per fiber and range; the FilterScalarRanges block
  std::string scalar_key_;                     // the values scalar_values_ holds (a hash)
  bool has_zone_ = false;
  std::vector<gpu::Buffer> masks_;  // the voxel bits of mask regions
  std::string signature_;           // criteria and sources of the last update
  bool active_ = false, raw_ = false;
  uint32_t fibers_ = 0;
  uint64_t kept_count_ = 0;
  double last_ms_ = 0;
};

}  // namespace fibscope
