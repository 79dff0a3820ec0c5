#include "select/fiber_filter.h"

#include <string>

#include "core/error.h"

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

}  // namespace

bool FilterCriteria::empty() const {
  return include.empty() && include_ordered.empty() && exclude.empty() && std::isnan(min_length_mm) &&
         std::isnan(max_length_mm);
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
  const float margin = std::isfinite(step_size_mm) ? 0.1f * step_size_mm : 0.0f;
  if (!std::isnan(lo)) min_length_ = float(lo) - margin;
  if (!std::isnan(hi)) max_length_ = float(hi) + margin;
}

FilterVerdict FiberFilter::evaluate(const float* xyz, size_t n) const {
  return evaluate(xyz, n, lengthInFloat(xyz, n));
}

FilterVerdict FiberFilter::evaluate(const float* xyz, size_t n, float length) const {
  if (n == 0) length = NAN;
  if (!(length >= min_length_ && length <= max_length_)) return {FilterReason::Length, 0};
  const FilterCriteria& c = criteria_;
  if (c.include.empty() && c.include_ordered.empty() && c.exclude.empty()) return {};
  // Which include regions a vertex has reached (a bit each: no allocation
  // per streamline, at most kMaxRegions), and the ordered ones' progress:
  // `next` to enter, the order broken or not.
  uint64_t reached = 0;
  size_t next = 0;
  bool in_order = true;
  // The exclude region p lies in, or -1 after noting p's includes.
  auto visit = [&](const float* p) -> int {
    for (size_t r = 0; r < c.include.size(); ++r)
      if (!(reached >> r & 1u) && regionContains(c.include[r], p)) reached |= uint64_t(1) << r;
    if (in_order)
      for (size_t r = 0; r < c.include_ordered.size(); ++r)
        if (regionContains(c.include_ordered[r], p)) {
          if (r == next) ++next;
          else if (r + 1 != next) in_order = false;
          break;
        }
    for (size_t r = 0; r < c.exclude.size(); ++r)
      if (regionContains(c.exclude[r], p)) return int(r);
    return -1;
  };
  if (c.ends_only) {
    for (const float* p : {xyz, xyz + 3 * (n - 1)})
      if (const int r = visit(p); r >= 0) return {FilterReason::Exclude, uint32_t(r)};
  } else {
    for (size_t i = 0; i < n; ++i)
      if (const int r = visit(xyz + 3 * i); r >= 0) return {FilterReason::Exclude, uint32_t(r)};
  }
  for (size_t r = 0; r < c.include.size(); ++r)
    if (!(reached >> r & 1u)) return {FilterReason::Include, uint32_t(r)};
  if (!in_order || next != c.include_ordered.size())
    return {FilterReason::IncludeOrdered, uint32_t(in_order ? next : 0)};
  return {};
}

}  // namespace fibscope
