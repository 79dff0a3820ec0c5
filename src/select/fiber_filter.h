// Which streamlines a set of criteria keeps: the semantics of MRtrix3's
// tckedit (3.0), so that `fibscope filter` and `tckedit` keep the same
// streamlines, and the GPU kept-bit pass (later) the same as both.
//
// For each streamline, in this order:
//   1. length: the sum of its segments' lengths in float (0 for one point,
//      NaN, so dropped, for none) within [min_length - m, max_length + m],
//      m = 0.1 x the file's step size where the header states one
//      ("output_step_size", else "step_size"), else 0 (tckedit's margin for
//      lengths computed in float);
//   1b. per-fiber scalars from the file (select/scalar_range.h; not a
//      tckedit criterion): each range's value within [min, max] (open ends
//      unbounded); a NaN value is dropped, whatever the range;
//   2. the vertices (only the first and the last with ends_only), in order:
//      one inside any exclude region drops the streamline; every include
//      region must contain at least one vertex; the ordered includes must
//      be entered in their order: a vertex in ordered region k (the first
//      that contains it) is fine when k is the next one to enter or the one
//      entered last, anything else breaks the order;
// and it is kept when it passes all of them.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/tractogram.h"
#include "select/region.h"
#include "select/scalar_range.h"
#include "shared/fiber_filter.h"

namespace fibscope {

struct FilterCriteria {
  std::vector<Region> include;          // each must contain a vertex (tckedit -include)
  std::vector<Region> include_ordered;  // entered in this order (tckedit -include_ordered)
  std::vector<Region> exclude;          // none may contain a vertex (tckedit -exclude)
  bool ends_only = false;               // test only the two end vertices (tckedit -ends_only)
  double min_length_mm = NAN;           // NaN: no limit
  double max_length_mm = NAN;
  // Distance to a zone (the fiblets paper's figure 11 e, f): the smallest
  // distance from any vertex (every vertex, ends_only or not) to a point
  // (a sphere of radius 0), a sphere, a box or an oriented box (0 inside);
  // kept only when it is <= max_distance_mm (NaN: no threshold, the
  // distance is only measured, e.g. for colouring). Decided on squared
  // distances in float (shared/fiber_filter.h), alike on the CPU and GPU.
  std::optional<Region> distance_zone;
  double max_distance_mm = NAN;
  // Per-fiber scalars in ranges (trk properties, TRX dps): the caller
  // gives each streamline's values of these, in this order (evaluate's
  // `scalars`; resolveScalarColumns finds them in a file's arrays).
  std::vector<ScalarRange> scalar_ranges;
  // No criterion drops anything (a zone without a threshold drops nothing).
  bool empty() const;
};

// Why a streamline was dropped (Kept: it was not).
enum class FilterReason : uint8_t { Kept, Length, Scalar, Exclude, Include, IncludeOrdered, Distance };

struct FilterVerdict {
  FilterReason reason = FilterReason::Kept;
  uint32_t region = 0;  // Exclude / Include / IncludeOrdered: the region's index in its list; Scalar: the range's
  bool kept() const { return reason == FilterReason::Kept; }
};

// The step size the file's header states (tck: "output_step_size", else
// "step_size"; a number > 0), or NaN.
float headerStepSize(const TractogramHeader& header);

class FiberFilter {
 public:
  static constexpr size_t kMaxRegions = 64;  // of each kind
  static constexpr size_t kMaxScalarRanges = shader::kFilterMaxScalarRanges;
  // Throws Error for a min length above the max length or a negative one,
  // more than kMaxRegions regions of a kind, a scalar range whose min is
  // above its max, or more than kMaxScalarRanges of them.
  FiberFilter(FilterCriteria criteria, float step_size_mm = NAN);
  const FilterCriteria& criteria() const { return criteria_; }

  // The verdict for the streamline of n points (x, y, z interleaved) whose
  // per-fiber values of criteria().scalar_ranges are `scalars` (one per
  // range, in their order: the caller must give exactly that many).
  FilterVerdict evaluate(const float* xyz, size_t n, std::span<const float> scalars = {}) const;
  // The same with its length given (mm; NaN drops it) instead of summed
  // from the points: the GPU filter reads the lengths computed at upload,
  // and its tests compare with this.
  FilterVerdict evaluate(const float* xyz, size_t n, float length_mm, std::span<const float> scalars = {}) const;
  // The index of the first range `scalars` misses, or -1 when in all.
  int scalarOutside(std::span<const float> scalars) const;
  // Range i's bounds as floats, as both sides compare them
  // (shader::filterScalarInRange): -inf / +inf for an open end.
  float scalarMin(size_t i) const { return scalar_lo_[i]; }
  float scalarMax(size_t i) const { return scalar_hi_[i]; }
  // The length limits with the margin (-inf / +inf without a limit).
  float minLength() const { return min_length_; }
  float maxLength() const { return max_length_; }
  // The zone as the tests run on it, and the squared threshold its
  // distances are compared with (+inf without one); the zone's smallest
  // distance from the streamline (mm; +inf for no points, 0 inside).
  const shader::FilterRegion* zone() const { return has_zone_ ? &zone_ : nullptr; }
  float maxZoneDistance2() const { return max_zone_d2_; }
  float zoneDistance(const float* xyz, size_t n) const;

 private:
  // A region in the form the tests run on (select/packed_region.h: the
  // floats and the box the GPU filter gets too), with its mask.
  struct Packed {
    shader::FilterRegion region;
    const VoxelMask* mask = nullptr;
  };
  FilterCriteria criteria_;
  std::vector<Packed> include_, include_ordered_, exclude_;
  shader::FilterRegion zone_{};
  bool has_zone_ = false;
  float max_zone_d2_ = INFINITY;
  float zoneDistance2(const float* xyz, size_t n) const;
  FilterVerdict evaluateRegions(const float* xyz, size_t n) const;
  FilterVerdict evaluateEnds(const float* xyz, size_t n) const;  // ends_only
  // One point of the ordered-include walk, over the regions in `among`.
  void orderedStep(uint64_t among, const float* p, size_t& next, bool& in_order) const;
  static bool contains(const Packed& r, const float* p);
  float min_length_ = -INFINITY, max_length_ = INFINITY;  // with the margin
  std::vector<float> scalar_lo_, scalar_hi_;
};

}  // namespace fibscope
