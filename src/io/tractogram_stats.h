// Geometry statistics of a tractogram, accumulated chunk by chunk
// (`fibscope info`). Memory is constant whatever the file size: medians and
// percentiles come from fixed histograms (step lengths at 1.2e-4 relative
// resolution, turning angles at 0.001 degree).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/tractogram.h"

namespace fibscope {

struct TractogramStats {
  uint64_t streamlines = 0;
  uint64_t points = 0;
  uint64_t segments = 0;
  uint64_t empty_streamlines = 0;   // 0 points
  uint64_t single_point_streamlines = 0;
  uint64_t zero_length_segments = 0;  // repeated points

  double step_min = 0, step_median = 0, step_max = 0;
  double step_within_1pct = 0;       // fraction of segments within 1 % of the median step
  // Turning angle between consecutive segments; percentiles are the upper
  // edge of their 0.001-degree bin (never above the max).
  double angle_mean_deg = 0, angle_p50_deg = 0, angle_p99_deg = 0, angle_p999_deg = 0, angle_max_deg = 0;
  std::array<double, 3> bbox_min{}, bbox_max{};
  double length_min = 0, length_mean = 0, length_max = 0;  // mm, along the polyline
};

class TractogramStatsAccumulator {
 public:
  TractogramStatsAccumulator();
  void add(const Tractogram& chunk);
  // Merges another accumulator (for parallel accumulation).
  void merge(const TractogramStatsAccumulator& other);
  TractogramStats result() const;

 private:
  static size_t stepBin(float step);
  static double stepBinValue(size_t bin);
  double anglePercentile(uint64_t angles, double fraction) const;

  TractogramStats s_;
  double length_sum_ = 0;
  double step_min_ = std::numeric_limits<double>::infinity(), step_max_ = 0;
  double angle_max_ = 0, angle_sum_ = 0;
  double length_min_ = std::numeric_limits<double>::infinity(), length_max_ = 0;
  std::array<double, 3> lo_, hi_;
  std::vector<uint64_t> step_hist_;
  std::vector<uint64_t> angle_hist_;
};

}  // namespace fibscope
