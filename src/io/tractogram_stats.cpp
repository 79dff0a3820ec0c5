#include "io/tractogram_stats.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace fibscope {
namespace {

// Step histogram: a float's bits above the low 10 mantissa bits are a
// monotone, log-spaced key (13 mantissa bits: 1.2e-4 relative bin width).
// Exponents from 2^-20 mm to 2^20 mm are kept; outside values clamp.
constexpr int kMantissaBits = 13;
constexpr uint32_t kMinExponent = 127 - 20, kMaxExponent = 127 + 20;
constexpr uint32_t kStepKeyMin = kMinExponent << kMantissaBits;
constexpr uint32_t kStepKeyMax = (kMaxExponent + 1) << kMantissaBits;
constexpr double kAngleBinDeg = 0.001;
constexpr size_t kAngleBins = 180001;

}  // namespace

TractogramStatsAccumulator::TractogramStatsAccumulator()
    : lo_{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity()},
      hi_{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity()},
      step_hist_(kStepKeyMax - kStepKeyMin, 0),
      angle_hist_(kAngleBins, 0) {}

size_t TractogramStatsAccumulator::stepBin(float step) {
  const uint32_t key = std::bit_cast<uint32_t>(step) >> (23 - kMantissaBits);
  return std::clamp(key, kStepKeyMin, kStepKeyMax - 1) - kStepKeyMin;
}

double TractogramStatsAccumulator::stepBinValue(size_t bin) {
  // Centre of the bin: the key with a half-unit of the dropped bits.
  const uint32_t bits = (static_cast<uint32_t>(bin + kStepKeyMin) << (23 - kMantissaBits)) | (1u << (22 - kMantissaBits));
  return std::bit_cast<float>(bits);
}

void TractogramStatsAccumulator::add(const Tractogram& t) {
  const float* p = t.positions.data();
  for (size_t i = 0; i < t.pointCount(); ++i)
    for (int k = 0; k < 3; ++k) {
      lo_[k] = std::min<double>(lo_[k], p[3 * i + k]);
      hi_[k] = std::max<double>(hi_[k], p[3 * i + k]);
    }
  s_.streamlines += t.streamlineCount();
  s_.points += t.pointCount();
  for (size_t f = 0; f < t.streamlineCount(); ++f) {
    const size_t begin = t.offsets[f], n = t.pointsIn(f);
    if (n == 0) ++s_.empty_streamlines;
    if (n == 1) ++s_.single_point_streamlines;
    if (n < 2) continue;
    s_.segments += n - 1;
    double length = 0;
    double prev[3] = {0, 0, 0};
    bool have_prev = false;
    for (size_t i = begin; i + 1 < begin + n; ++i) {
      // Differences in double: a float subtraction of two coordinates would
      // round the step (e.g. 50.1 - 49.9) before it is measured.
      const double d[3] = {double(p[3 * i + 3]) - p[3 * i], double(p[3 * i + 4]) - p[3 * i + 1],
                           double(p[3 * i + 5]) - p[3 * i + 2]};
      const double len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      const double step = std::sqrt(len2);
      length += step;
      if (step == 0) {
        ++s_.zero_length_segments;
        continue;  // no direction: neither a step sample nor an angle
      }
      step_min_ = std::min(step_min_, step);
      step_max_ = std::max(step_max_, step);
      ++step_hist_[stepBin(static_cast<float>(step))];
      if (have_prev) {
        const double dot = prev[0] * d[0] + prev[1] * d[1] + prev[2] * d[2];
        const double plen = std::sqrt(prev[0] * prev[0] + prev[1] * prev[1] + prev[2] * prev[2]);
        const double c = std::clamp(dot / (plen * step), -1.0, 1.0);
        const double angle = std::acos(c) * (180.0 / M_PI);
        angle_max_ = std::max(angle_max_, angle);
        angle_sum_ += angle;
        ++angle_hist_[std::min(kAngleBins - 1, static_cast<size_t>(angle / kAngleBinDeg))];
      }
      std::copy(d, d + 3, prev);
      have_prev = true;
    }
    length_sum_ += length;
    length_min_ = std::min(length_min_, length);
    length_max_ = std::max(length_max_, length);
  }
}

void TractogramStatsAccumulator::merge(const TractogramStatsAccumulator& o) {
  s_.streamlines += o.s_.streamlines;
  s_.points += o.s_.points;
  s_.segments += o.s_.segments;
  s_.empty_streamlines += o.s_.empty_streamlines;
  s_.single_point_streamlines += o.s_.single_point_streamlines;
  s_.zero_length_segments += o.s_.zero_length_segments;
  length_sum_ += o.length_sum_;
  step_min_ = std::min(step_min_, o.step_min_);
  step_max_ = std::max(step_max_, o.step_max_);
  angle_max_ = std::max(angle_max_, o.angle_max_);
  angle_sum_ += o.angle_sum_;
  length_min_ = std::min(length_min_, o.length_min_);
  length_max_ = std::max(length_max_, o.length_max_);
  for (int k = 0; k < 3; ++k) {
    lo_[k] = std::min(lo_[k], o.lo_[k]);
    hi_[k] = std::max(hi_[k], o.hi_[k]);
  }
  for (size_t i = 0; i < step_hist_.size(); ++i) step_hist_[i] += o.step_hist_[i];
  for (size_t i = 0; i < angle_hist_.size(); ++i) angle_hist_[i] += o.angle_hist_[i];
}

// The smallest bin edge with at least `fraction` of the samples at or below it.
double TractogramStatsAccumulator::anglePercentile(uint64_t angles, double fraction) const {
  const auto target = static_cast<uint64_t>(std::ceil(fraction * double(angles)));
  uint64_t seen = 0;
  for (size_t i = 0; i < angle_hist_.size(); ++i) {
    seen += angle_hist_[i];
    if (seen >= target) return std::min(angle_max_, (double(i) + 1) * kAngleBinDeg);
  }
  return angle_max_;
}

TractogramStats TractogramStatsAccumulator::result() const {
  TractogramStats r = s_;
  const uint64_t steps = r.segments - r.zero_length_segments;
  if (steps > 0) {
    r.step_min = step_min_;
    r.step_max = step_max_;
    // Median: the bin holding the middle sample.
    uint64_t seen = 0;
    size_t median_bin = 0;
    for (size_t i = 0; i < step_hist_.size(); ++i) {
      seen += step_hist_[i];
      if (2 * seen >= steps) {
        median_bin = i;
        break;
      }
    }
    r.step_median = std::clamp(stepBinValue(median_bin), step_min_, step_max_);
    // Bins whose centre lies within 1 % of the median (bin width 1.2e-4).
    const size_t lo = stepBin(static_cast<float>(r.step_median * 0.99));
    const size_t hi = stepBin(static_cast<float>(r.step_median * 1.01));
    uint64_t within = 0;
    for (size_t i = lo; i <= hi; ++i) within += step_hist_[i];
    r.step_within_1pct = double(within) / double(steps);
  }
  uint64_t angles = 0;
  for (uint64_t c : angle_hist_) angles += c;
  if (angles > 0) {
    r.angle_max_deg = angle_max_;
    r.angle_mean_deg = angle_sum_ / double(angles);
    r.angle_p50_deg = anglePercentile(angles, 0.5);
    r.angle_p99_deg = anglePercentile(angles, 0.99);
    r.angle_p999_deg = anglePercentile(angles, 0.999);
  }
  if (r.points > 0) {
    r.bbox_min = lo_;
    r.bbox_max = hi_;
  }
  const uint64_t measured = r.streamlines - r.empty_streamlines - r.single_point_streamlines;
  if (measured > 0) {
    r.length_min = length_min_;
    r.length_max = length_max_;
    r.length_mean = length_sum_ / double(measured);
  }
  return r;
}

}  // namespace fibscope
