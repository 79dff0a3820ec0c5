#include "core/tractogram.h"

#include <algorithm>
#include <cmath>

namespace fibscope {

void Tractogram::clear() {
  positions.clear();
  offsets.assign(1, 0);
  for (auto& a : per_streamline) a.values.clear();
  for (auto& a : per_point) a.values.clear();
}

void Tractogram::addStreamline(const float* xyz, size_t n) {
  positions.insert(positions.end(), xyz, xyz + 3 * n);
  offsets.push_back(offsets.back() + n);
}

void Tractogram::append(const Tractogram& other) {
  const uint64_t base = offsets.back();
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  offsets.reserve(offsets.size() + other.streamlineCount());
  for (size_t i = 1; i < other.offsets.size(); ++i) offsets.push_back(base + other.offsets[i]);
  auto merge = [](std::vector<DataArray>& into, const std::vector<DataArray>& from) {
    if (into.empty()) {
      for (const auto& a : from) into.push_back({a.name, a.components, a.dtype, {}});
    }
    for (size_t i = 0; i < std::min(into.size(), from.size()); ++i)
      into[i].values.insert(into[i].values.end(), from[i].values.begin(), from[i].values.end());
  };
  merge(per_streamline, other.per_streamline);
  merge(per_point, other.per_point);
}

std::string Tractogram::validate() const {
  if (offsets.empty() || offsets[0] != 0) return "offsets must start with 0";
  for (size_t i = 1; i < offsets.size(); ++i)
    if (offsets[i] < offsets[i - 1]) return "offsets decrease at streamline " + std::to_string(i - 1);
  if (positions.size() != 3 * pointCount())
    return "positions hold " + std::to_string(positions.size()) + " floats, expected " +
           std::to_string(3 * pointCount());
  for (const auto& a : per_streamline)
    if (a.values.size() != streamlineCount() * a.components)
      return "per-streamline array '" + a.name + "' has " + std::to_string(a.values.size()) + " values, expected " +
             std::to_string(streamlineCount() * a.components);
  for (const auto& a : per_point)
    if (a.values.size() != pointCount() * a.components)
      return "per-point array '" + a.name + "' has " + std::to_string(a.values.size()) + " values, expected " +
             std::to_string(pointCount() * a.components);
  return {};
}

std::string TractogramHeader::property(const std::string& key) const {
  for (const auto& [k, v] : properties)
    if (k == key) return v;
  return {};
}

float polylineLength(const float* p, size_t n) {
  double length = 0;
  for (size_t i = 1; i < n; ++i) {
    const float* a = p + 3 * (i - 1);
    const float* b = a + 3;
    const double dx = double(b[0]) - a[0], dy = double(b[1]) - a[1], dz = double(b[2]) - a[2];
    const float d = std::sqrt(float(dx * dx + dy * dy + dz * dz));
    if (std::isfinite(d)) length += d;
  }
  return float(length);
}

}  // namespace fibscope
