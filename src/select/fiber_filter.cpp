#include "select/fiber_filter.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <string>

#include "core/error.h"
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
  return evaluate(xyz, n, lengthInFloat(xyz, n), scalars);
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
  // The vertices tested: all, or the two ends.
  const size_t visits = criteria_.ends_only ? 2 : n;
  auto vertex = [&](size_t i) { return criteria_.ends_only ? xyz + (i == 0 ? 0 : 3 * (n - 1)) : xyz + 3 * i; };
  // The streamline's box: a region whose box it misses holds none of its
  // vertices, so most regions are decided for most streamlines without a
  // test per vertex (this is where the time went: a test per vertex and
  // region).
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  if (criteria_.ends_only) {
    for (size_t i = 0; i < 2; ++i)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], vertex(i)[k]);
        hi[k] = std::max(hi[k], vertex(i)[k]);
      }
  } else {
    // Straight over the points, in the form the compiler vectorises
    // (a < b ? a : b is minps; a NaN coordinate is in no region anyway).
    float lx = INFINITY, ly = INFINITY, lz = INFINITY, hx = -INFINITY, hy = -INFINITY, hz = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
      const float x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
      lx = x < lx ? x : lx;
      ly = y < ly ? y : ly;
      lz = z < lz ? z : lz;
      hx = x > hx ? x : hx;
      hy = y > hy ? y : hy;
      hz = z > hz ? z : hz;
    }
    lo[0] = lx, lo[1] = ly, lo[2] = lz, hi[0] = hx, hi[1] = hy, hi[2] = hz;
  }
  auto near = [&](const Packed& r) {
    const float* b = r.region.box;
    return !(hi[0] < b[0] || lo[0] > b[3] || hi[1] < b[1] || lo[1] > b[4] || hi[2] < b[2] || lo[2] > b[5]);
  };
  auto contains = [](const Packed& r, const float* p) {
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
  };
  // In the verdict's order: an exclude region entered (the first vertex
  // in one, its first region), an include missed (the first), the ordered
  // includes; as tckedit decides each, whatever order they are tested in.
  uint64_t candidates = 0;
  for (size_t r = 0; r < exclude_.size(); ++r)
    if (near(exclude_[r])) candidates |= uint64_t(1) << r;
  if (candidates != 0)
    for (size_t i = 0; i < visits; ++i)
      for (size_t r = 0; r < exclude_.size(); ++r)
        if ((candidates >> r & 1u) && contains(exclude_[r], vertex(i))) return {FilterReason::Exclude, uint32_t(r)};
  for (size_t r = 0; r < include_.size(); ++r) {
    bool reached = false;
    if (near(include_[r]))
      for (size_t i = 0; i < visits && !reached; ++i) reached = contains(include_[r], vertex(i));
    if (!reached) return {FilterReason::Include, uint32_t(r)};
  }
  if (include_ordered_.empty()) return {};
  // The ordered includes: a vertex in ordered region k (the first that
  // contains it) is fine when k is the next one to enter or the one entered
  // last; anything else breaks the order.
  candidates = 0;
  for (size_t r = 0; r < include_ordered_.size(); ++r)
    if (near(include_ordered_[r])) candidates |= uint64_t(1) << r;
  size_t next = 0;
  bool in_order = true;
  for (size_t i = 0; i < visits && in_order && candidates != 0; ++i)
    for (size_t r = 0; r < include_ordered_.size(); ++r)
      if ((candidates >> r & 1u) && contains(include_ordered_[r], vertex(i))) {
        if (r == next) ++next;
        else if (r + 1 != next) in_order = false;
        break;
      }
  if (!in_order || next != include_ordered_.size())
    return {FilterReason::IncludeOrdered, uint32_t(in_order ? next : 0)};
  return {};
}

}  // namespace fibscope
