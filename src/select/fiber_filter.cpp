#include "select/fiber_filter.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <string>

#include "core/error.h"
#include "select/block_boxes.h"
#include "select/packed_region.h"
#include "select/voxel_mask.h"

namespace fibscope {
namespace {

// tckedit's Tractography::length: float norms summed in float.
float lengthInFloat(const float* xyz, size_t n) {
  if (n == 0) return NAN;
  float total = 0;
  for (size_t i = 1; i < n; ++i) {
    const float* a = xyz + 3 * (i - 1);
    const float* b = xyz + 3 * i;
    const float dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
    total += std::sqrt((dx * dx + dy * dy) + dz * dz);
  }
  return total;
}

// The float nearest `bound` on the kept side (up for a min, down for a
// max), so that a float value compares with it as with the double.
float keptSideFloat(double bound, bool is_min) {
  if (std::isnan(bound)) return is_min ? -INFINITY : INFINITY;
  // Beyond a float's range (converting would be undefined): the float
  // infinity on the bound's side, or the largest float on the kept side.
  constexpr double kMax = std::numeric_limits<float>::max();
  if (bound > kMax) return is_min ? INFINITY : float(kMax);
  if (bound < -kMax) return is_min ? -float(kMax) : -INFINITY;
  float f = float(bound);
  if (is_min && double(f) < bound) f = std::nextafter(f, INFINITY);
  if (!is_min && double(f) > bound) f = std::nextafter(f, -INFINITY);
  return f;
}

}  // namespace

bool FilterCriteria::empty() const {
  return include.empty() && include_ordered.empty() && exclude.empty() && scalar_ranges.empty() &&
         std::isnan(min_length_mm) &&
         std::isnan(max_length_mm) && (!distance_zone || std::isnan(max_distance_mm));
}

float headerStepSize(const TractogramHeader& header) {
  for (const char* key : {"output_step_size", "step_size"}) {
    const std::string text = header.property(key);
    if (text.empty()) continue;
    char* end = nullptr;
    const float v = std::strtof(text.c_str(), &end);
    return end != text.c_str() && std::isfinite(v) && v > 0 ? v : NAN;
  }
  return NAN;
}

FiberFilter::FiberFilter(FilterCriteria criteria, float step_size_mm) : criteria_(std::move(criteria)) {
  const double lo = criteria_.min_length_mm, hi = criteria_.max_length_mm;
  if (lo < 0 || hi < 0) throw Error("filter: lengths must be >= 0 mm");
  if (lo > hi) throw Error("filter: the minimum length is above the maximum length");
  for (const auto* list : {&criteria_.include, &criteria_.include_ordered, &criteria_.exclude})
    if (list->size() > kMaxRegions)
      throw Error("filter: at most " + std::to_string(kMaxRegions) + " regions of each kind");
  if (criteria_.scalar_ranges.size() > kMaxScalarRanges)
    throw Error("filter: at most " + std::to_string(kMaxScalarRanges) + " scalar ranges");
  for (const ScalarRange& r : criteria_.scalar_ranges) {
    checkScalarRange(r, "filter: scalar range " + scalarRangeSpec(r));
    scalar_lo_.push_back(keptSideFloat(r.min, true));
    scalar_hi_.push_back(keptSideFloat(r.max, false));
  }
  const float margin = std::isfinite(step_size_mm) ? 0.1f * step_size_mm : 0.0f;
  if (!std::isnan(lo)) min_length_ = float(lo) - margin;
  if (!std::isnan(hi)) max_length_ = float(hi) + margin;
  auto pack = [](const std::vector<Region>& regions, std::vector<Packed>& out) {
    for (const Region& r : regions) {
      const auto* m = std::get_if<MaskRegion>(&r);
      out.push_back({packRegion(r), m ? m->mask.get() : nullptr});
    }
  };
  pack(criteria_.include, include_);
  pack(criteria_.include_ordered, include_ordered_);
  pack(criteria_.exclude, exclude_);
  if (criteria_.distance_zone) {
    if (std::holds_alternative<MaskRegion>(*criteria_.distance_zone))
      throw Error("filter: a distance zone is a point, a sphere, a box or an oriented box, not a mask");
    zone_ = packRegion(*criteria_.distance_zone);
    has_zone_ = true;
    const double t = criteria_.max_distance_mm;
    if (t < 0) throw Error("filter: the distance threshold must be >= 0 mm");
    if (!std::isnan(t)) {
      // A sphere's distances are from its centre, less its radius.
      const float reach = zone_.kind == shader::kFilterSphere ? float(t) + zone_.v[3] : float(t);
      max_zone_d2_ = reach * reach;
    }
  }
}

float FiberFilter::zoneDistance2(const float* xyz, size_t n) const {
  const shader::FilterRegion& z = zone_;
  const shader::vec3 a0(z.v[6], z.v[7], z.v[8]), a1(z.v[9], z.v[10], z.v[11]), a2(z.v[12], z.v[13], z.v[14]);
  float best = INFINITY;
  for (size_t i = 0; i < n; ++i) {
    const float* p = xyz + 3 * i;
    const float d2 = shader::filterDistance2(z.kind, z.v[0], z.v[1], z.v[2], z.v[3], z.v[4], z.v[5], a0, a1, a2,
                                             shader::vec3(p[0], p[1], p[2]));
    best = d2 < best ? d2 : best;
  }
  return best;
}

float FiberFilter::zoneDistance(const float* xyz, size_t n) const {
  if (!has_zone_) return NAN;
  const float d = std::sqrt(zoneDistance2(xyz, n)) - (zone_.kind == shader::kFilterSphere ? zone_.v[3] : 0.0f);
  return d > 0 ? d : 0.0f;
}

FilterVerdict FiberFilter::evaluate(const float* xyz, size_t n, std::span<const float> scalars) const {
  // Without limits only "no points" counts (NaN, dropped as tckedit drops
  // an empty streamline), and summing a square root per point was a sixth
  // of `fibscope filter`'s time.
  const bool limited = min_length_ > -INFINITY || max_length_ < INFINITY;
  return evaluate(xyz, n, limited ? lengthInFloat(xyz, n) : n == 0 ? NAN : 0.0f, scalars);
}

int FiberFilter::scalarOutside(std::span<const float> scalars) const {
  assert(scalars.size() == scalar_lo_.size());
  for (size_t i = 0; i < scalar_lo_.size(); ++i)
    if (!shader::filterScalarInRange(scalars[i], scalar_lo_[i], scalar_hi_[i])) return int(i);
  return -1;
}

FilterVerdict FiberFilter::evaluate(const float* xyz, size_t n, float length, std::span<const float> scalars) const {
  if (n == 0) length = NAN;
  if (!(length >= min_length_ && length <= max_length_)) return {FilterReason::Length, 0};
  if (const int r = scalarOutside(scalars); r >= 0) return {FilterReason::Scalar, uint32_t(r)};
  const FilterVerdict regions = evaluateRegions(xyz, n);
  if (!regions.kept()) return regions;
  if (has_zone_ && !(zoneDistance2(xyz, n) <= max_zone_d2_)) return {FilterReason::Distance, 0};
  return {};
}

FilterVerdict FiberFilter::evaluateRegions(const float* xyz, size_t n) const {
  if (include_.empty() && include_ordered_.empty() && exclude_.empty()) return {};
  if (criteria_.ends_only) return evaluateEnds(xyz, n);
  // The streamline's box and its runs' boxes (select/block_boxes.h): a
  // region whose box a run's misses holds none of the run's points, so most
  // regions are decided for most streamlines without a test per point, and
  // the streamlines that come near one are tested in the runs that do
  // (this is where the time went: a test per point and region).
  thread_local BlockBoxes runs;
  computeBlockBoxes(xyz, n, runs);
  const float whole[6] = {runs.lo[0], runs.lo[1], runs.lo[2], runs.hi[0], runs.hi[1], runs.hi[2]};
  constexpr size_t B = BlockBoxes::kBlockPoints;
  // The regions of `list` whose boxes meet `box`, among `among`.
  auto meeting = [](const std::vector<Packed>& list, const float* box, uint64_t among) {
    uint64_t m = 0;
    for (size_t r = 0; r < list.size(); ++r)
      if ((among >> r & 1u) && boxesMeet(box, list[r].region.box)) m |= uint64_t(1) << r;
    return m;
  };
  const uint64_t all = ~uint64_t(0);
  // In the verdict's order: an exclude region entered (the first point in
  // one, its first region), an include missed (the first), the ordered
  // includes; as tckedit decides each, whatever order they are tested in.
  if (const uint64_t near = meeting(exclude_, whole, all))
    for (size_t b = 0; b < runs.blocks(); ++b)
      if (const uint64_t here = meeting(exclude_, runs.box(b), near))
        for (size_t i = B * b; i < std::min(n, B * (b + 1)); ++i)
          for (size_t r = 0; r < exclude_.size(); ++r)
            if ((here >> r & 1u) && contains(exclude_[r], xyz + 3 * i)) return {FilterReason::Exclude, uint32_t(r)};
  for (size_t r = 0; r < include_.size(); ++r) {
    bool reached = false;
    if (boxesMeet(whole, include_[r].region.box))
      for (size_t b = 0; b < runs.blocks() && !reached; ++b)
        if (boxesMeet(runs.box(b), include_[r].region.box))
          for (size_t i = B * b; i < std::min(n, B * (b + 1)) && !reached; ++i)
            reached = contains(include_[r], xyz + 3 * i);
    if (!reached) return {FilterReason::Include, uint32_t(r)};
  }
  if (include_ordered_.empty()) return {};
  // The ordered includes: a point in ordered region k (the first that
  // contains it) is fine when k is the next one to enter or the one entered
  // last; anything else breaks the order. A run near none of them holds no
  // point in any, so it changes nothing.
  const uint64_t near = meeting(include_ordered_, whole, all);
  size_t next = 0;
  bool in_order = true;
  for (size_t b = 0; b < runs.blocks() && in_order && near != 0; ++b) {
    const uint64_t here = meeting(include_ordered_, runs.box(b), near);
    for (size_t i = B * b; i < std::min(n, B * (b + 1)) && in_order && here != 0; ++i)
      orderedStep(here, xyz + 3 * i, next, in_order);
  }
  if (!in_order || next != include_ordered_.size())
    return {FilterReason::IncludeOrdered, uint32_t(in_order ? next : 0)};
  return {};
}

FilterVerdict FiberFilter::evaluateEnds(const float* xyz, size_t n) const {
  // tckedit -ends_only: the first and the last point (the same one for a
  // streamline of one; none for an empty one).
  const float* ends[2] = {xyz, n ? xyz + 3 * (n - 1) : xyz};
  const size_t visits = n == 0 ? 0 : 2;
  for (size_t i = 0; i < visits; ++i)
    for (size_t r = 0; r < exclude_.size(); ++r)
      if (contains(exclude_[r], ends[i])) return {FilterReason::Exclude, uint32_t(r)};
  for (size_t r = 0; r < include_.size(); ++r) {
    bool reached = false;
    for (size_t i = 0; i < visits && !reached; ++i) reached = contains(include_[r], ends[i]);
    if (!reached) return {FilterReason::Include, uint32_t(r)};
  }
  if (include_ordered_.empty()) return {};
  size_t next = 0;
  bool in_order = true;
  for (size_t i = 0; i < visits && in_order; ++i) orderedStep(~uint64_t(0), ends[i], next, in_order);
  if (!in_order || next != include_ordered_.size())
    return {FilterReason::IncludeOrdered, uint32_t(in_order ? next : 0)};
  return {};
}

void FiberFilter::orderedStep(uint64_t among, const float* p, size_t& next, bool& in_order) const {
  for (size_t r = 0; r < include_ordered_.size(); ++r)
    if ((among >> r & 1u) && contains(include_ordered_[r], p)) {
      if (r == next) ++next;
      else if (r + 1 != next) in_order = false;
      return;
    }
}

bool FiberFilter::contains(const Packed& r, const float* p) {
  const shader::FilterRegion& g = r.region;
  const shader::vec3 q(p[0], p[1], p[2]);
  switch (g.kind) {
    case shader::kFilterSphere: return shader::filterSphereContains(g.v[0], g.v[1], g.v[2], g.v[3], q);
    case shader::kFilterBox: return shader::filterBoxContains(g.v[0], g.v[1], g.v[2], g.v[3], g.v[4], g.v[5], q);
    case shader::kFilterOrientedBox:
      return shader::filterOrientedBoxContains({g.v[0], g.v[1], g.v[2]}, {g.v[3], g.v[4], g.v[5]},
                                               {g.v[6], g.v[7], g.v[8]}, {g.v[9], g.v[10], g.v[11]},
                                               {g.v[12], g.v[13], g.v[14]}, q);
    default: return r.mask->contains(p);
  }
}

}  // namespace fibscope
