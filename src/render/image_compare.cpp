#include "render/image_compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/error.h"

namespace fibscope {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// One-dimensional squared distance transform (Felzenszwalb & Huttenlocher,
// "Distance Transforms of Sampled Functions", 2012): out[q] = min over p of
// (q - p)^2 + f[p], by the lower envelope of the parabolas rooted at the
// finite samples. Infinite samples contribute no parabola.
void distanceTransform1d(const std::vector<double>& f, std::vector<double>& out, std::vector<size_t>& roots,
                         std::vector<double>& bounds) {
  const size_t n = f.size();
  roots.clear();
  bounds.clear();
  for (size_t q = 0; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;
    // Drop the parabolas the new one hides: those whose crossing with it
    // lies at or left of where they begin to be the lowest.
    double s = -kInf;
    while (!roots.empty()) {
      const size_t p = roots.back();
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (double(q) - double(p)));
      if (s > bounds.back()) break;
      roots.pop_back();
      bounds.pop_back();
      s = -kInf;
    }
    roots.push_back(q);
    bounds.push_back(s);
  }
  if (roots.empty()) {
    std::fill(out.begin(), out.end(), kInf);
    return;
  }
  size_t k = 0;
  for (size_t q = 0; q < n; ++q) {
    while (k + 1 < roots.size() && bounds[k + 1] < double(q)) ++k;
    const double d = double(q) - double(roots[k]);
    out[q] = d * d + f[roots[k]];
  }
}

}  // namespace

std::vector<double> squaredDistanceToCovered(const std::vector<uint8_t>& mask, uint32_t width, uint32_t height) {
  if (mask.size() != size_t(width) * height)
    fail("image compare", "mask has " + std::to_string(mask.size()) + " bytes, expected " +
                              std::to_string(size_t(width) * height) + " (" + std::to_string(width) + " x " +
                              std::to_string(height) + ")");
  std::vector<double> dist(mask.size());
  for (size_t i = 0; i < mask.size(); ++i) dist[i] = mask[i] ? 0.0 : kInf;
  std::vector<size_t> roots;
  std::vector<double> bounds;
  // Columns, then rows: the squared Euclidean distance is separable.
  std::vector<double> line(height), result(height);
  for (uint32_t x = 0; x < width; ++x) {
    for (uint32_t y = 0; y < height; ++y) line[y] = dist[size_t(y) * width + x];
    distanceTransform1d(line, result, roots, bounds);
    for (uint32_t y = 0; y < height; ++y) dist[size_t(y) * width + x] = result[y];
  }
  line.resize(width);
  result.resize(width);
  for (uint32_t y = 0; y < height; ++y) {
    std::copy_n(dist.begin() + std::ptrdiff_t(size_t(y) * width), width, line.begin());
    distanceTransform1d(line, result, roots, bounds);
    std::copy_n(result.begin(), width, dist.begin() + std::ptrdiff_t(size_t(y) * width));
  }
  return dist;
}

CoverageComparison compareCoverage(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, uint32_t width,
                                   uint32_t height) {
  const std::vector<double> to_b = squaredDistanceToCovered(b, width, height);
  const std::vector<double> to_a = squaredDistanceToCovered(a, width, height);
  CoverageComparison c;
  c.width = width;
  c.height = height;
  double worst_a = 0, worst_b = 0;  // squared
  for (size_t i = 0; i < a.size(); ++i) {
    const bool in_a = a[i] != 0, in_b = b[i] != 0;
    c.covered_a += in_a;
    c.covered_b += in_b;
    c.covered_both += in_a && in_b;
    if (in_a && !in_b) worst_a = std::max(worst_a, to_b[i]);
    if (in_b && !in_a) worst_b = std::max(worst_b, to_a[i]);
  }
  const size_t either = c.covered_a + c.covered_b - c.covered_both;
  c.agreement = either == 0 ? 1.0 : double(c.covered_both) / double(either);
  c.max_distance_a_to_b = std::sqrt(worst_a);
  c.max_distance_b_to_a = std::sqrt(worst_b);
  return c;
}

double CoverageComparison::maxDistance() const { return std::max(max_distance_a_to_b, max_distance_b_to_a); }

std::string CoverageComparison::summary() const {
  char text[256];
  std::snprintf(text, sizeof text,
                "%ux%u: A %zu px, B %zu px, both %zu px, agreement %.4f, max distance %.2f px (A->B %.2f, B->A %.2f)",
                width, height, covered_a, covered_b, covered_both, agreement, maxDistance(), max_distance_a_to_b,
                max_distance_b_to_a);
  return text;
}

}  // namespace fibscope
