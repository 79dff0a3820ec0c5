// Phantom statistics: one pass over a sample of streamlines.
#include "phantom/phantom_stats.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

namespace fibscope {
namespace {

constexpr double kBinsPerDegree = 100.0;
constexpr size_t kAngleBins = 180 * 100 + 1;

double percentile(const std::vector<uint64_t>& histogram, uint64_t total, double fraction) {
  if (total == 0) return 0;
  const auto wanted = uint64_t(std::ceil(fraction * double(total)));
  uint64_t seen = 0;
  for (size_t bin = 0; bin < histogram.size(); ++bin) {
    seen += histogram[bin];
    if (seen >= wanted) return double(bin + 1) / kBinsPerDegree;
  }
  return double(histogram.size()) / kBinsPerDegree;
}

}  // namespace

PhantomEstimate estimatePhantom(const PhantomOptions& options, uint64_t sample_streamlines) {
  PhantomOptions sample_options = options;
  sample_options.streamlines = std::min(options.streamlines, sample_streamlines);
  const auto start = std::chrono::steady_clock::now();
  auto reader = openPhantom(sample_options);

  PhantomEstimate e;
  std::vector<uint64_t> angle_histogram(kAngleBins, 0);
  double length_sum = 0, angle_sum = 0;
  uint64_t angles = 0;
  e.length_min_mm = e.segment_min_mm = std::numeric_limits<double>::infinity();
  Tractogram chunk;
  while (reader->read(chunk)) {
    const std::vector<float>& bundles = chunk.per_streamline[0].values;
    for (size_t s = 0; s < chunk.streamlineCount(); ++s) {
      const size_t first = chunk.offsets[s], count = chunk.pointsIn(s);
      double length = 0;
      double previous[3] = {0, 0, 0};
      for (size_t k = 1; k < count; ++k) {
        const float* a = chunk.point(first + k - 1);
        const float* b = chunk.point(first + k);
        const double d[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
        const double segment = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        length += segment;
        e.segment_min_mm = std::min(e.segment_min_mm, segment);
        e.segment_max_mm = std::max(e.segment_max_mm, segment);
        if (k >= 2) {
          // atan2(|u x v|, u . v) is accurate for small angles, where acos of
          // the normalised dot product loses half its digits.
          const double cx = previous[1] * d[2] - previous[2] * d[1], cy = previous[2] * d[0] - previous[0] * d[2],
                       cz = previous[0] * d[1] - previous[1] * d[0];
          const double angle = std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz),
                                          previous[0] * d[0] + previous[1] * d[1] + previous[2] * d[2]) *
                               (180.0 / 3.14159265358979323846);
          angle_sum += angle;
          ++angles;
          e.turn_max_deg = std::max(e.turn_max_deg, angle);
          ++angle_histogram[std::min(kAngleBins - 1, size_t(angle * kBinsPerDegree))];
        }
        previous[0] = d[0];
        previous[1] = d[1];
        previous[2] = d[2];
      }
      length_sum += length;
      e.length_min_mm = std::min(e.length_min_mm, length);
      e.length_max_mm = std::max(e.length_max_mm, length);
      const auto bundle = size_t(bundles[s]);
      if (bundle < kPhantomBundleCount) ++e.bundle_streamlines[bundle];
    }
    e.sampled_streamlines += chunk.streamlineCount();
    e.sampled_points += chunk.pointCount();
  }
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (e.sampled_streamlines == 0) {
    e.length_min_mm = e.segment_min_mm = 0;
    return e;
  }
  if (e.sampled_points == e.sampled_streamlines) e.segment_min_mm = 0;  // no segments at all
  e.sampled_segments = e.sampled_points - e.sampled_streamlines;
  e.length_mean_mm = length_sum / double(e.sampled_streamlines);
  e.turn_mean_deg = angles ? angle_sum / double(angles) : 0;
  e.turn_p50_deg = percentile(angle_histogram, angles, 0.5);
  e.turn_p99_deg = percentile(angle_histogram, angles, 0.99);
  e.turn_p999_deg = percentile(angle_histogram, angles, 0.999);

  const double points_per_streamline = double(e.sampled_points) / double(e.sampled_streamlines);
  if (e.sampled_streamlines == options.streamlines) {
    e.projected_points = e.sampled_points;
  } else {
    e.projected_points = uint64_t(std::llround(points_per_streamline * double(options.streamlines)));
  }
  e.projected_segments = e.projected_points - std::min(e.projected_points, options.streamlines);
  return e;
}

}  // namespace fibscope
