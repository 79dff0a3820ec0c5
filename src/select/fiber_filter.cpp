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
  const float margin = std::isfinite(step_size_mm) ? 0.1f * step_size_mm : 0.0f;
  if (!std::isnan(lo)) min_length_ = float(lo) - margin;
  if (!std::isnan(hi)) max_length_ = float(hi) + margin;
}

FilterVerdict FiberFilter::evaluate(const float* xyz, size_t n) const {
  const float length = lengthInFloat(xyz, n);
  if (!(length >= min_length_ && length <= max_length_)) return {FilterReason::Length, 0};
  const FilterCriteria& c = criteria_;
  if (c.include.empty() && c.include_ordered.empty() && c.exclude.empty()) return {};
  // Which include regions a vertex has reached, and the ordered ones'
  // progress: `next` to enter, the order broken or not.
  std::vector<char> reached(c.include.size(), 0);
  size_t next = 0;
  bool in_order = true;
  auto visit = [&](const float* p) -> bool {  // false: excluded
    for (size_t r = 0; r < c.include.size(); ++r)
      if (!reached[r] && regionContains(c.include[r], p)) reached[r] = 1;
    if (in_order)
      for (size_t r = 0; r < c.include_ordered.size(); ++r)
        if (regionContains(c.include_ordered[r], p)) {
          if (r == next) ++next;
          else if (r + 1 != next) in_order = false;
          break;
        }
    for (size_t r = 0; r < c.exclude.size(); ++r)
      if (regionContains(c.exclude[r], p)) return false;
    return true;
  };
  auto excludedBy = [&](const float* p) -> FilterVerdict {
    for (size_t r = 0; r < c.exclude.size(); ++r)
      if (regionContains(c.exclude[r], p)) return {FilterReason::Exclude, uint32_t(r)};
    return {};
  };
  if (c.ends_only) {
    for (const float* p : {xyz, xyz + 3 * (n - 1)})
      if (!visit(p)) return excludedBy(p);
  } else {
    for (size_t i = 0; i < n; ++i)
      if (!visit(xyz + 3 * i)) return excludedBy(xyz + 3 * i);
  }
  for (size_t r = 0; r < reached.size(); ++r)
    if (!reached[r]) return {FilterReason::Include, uint32_t(r)};
  if (!in_order || next != c.include_ordered.size())
    return {FilterReason::IncludeOrdered, uint32_t(in_order ? next : 0)};
  return {};
}

}  // namespace fibscope
