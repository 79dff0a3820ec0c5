// TractogramStatsAccumulator against brute-force statistics computed here
// with sorting (exact median and percentile).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "io/tractogram_stats.h"
#include "test_support.h"

namespace fibscope {
namespace {

struct BruteForce {
  std::vector<double> steps, angles, lengths;
};

BruteForce bruteForce(const Tractogram& t) {
  BruteForce b;
  for (size_t f = 0; f < t.streamlineCount(); ++f) {
    const size_t n = t.pointsIn(f);
    if (n < 2) continue;
    double length = 0;
    for (size_t i = t.offsets[f]; i + 1 < t.offsets[f + 1]; ++i) {
      const float* a = t.point(i);
      const float* c = t.point(i + 1);
      const double d[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
      const double s = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      b.steps.push_back(s);
      length += s;
      if (i > t.offsets[f]) {
        const float* z = t.point(i - 1);
        const double e[3] = {double(a[0]) - z[0], double(a[1]) - z[1], double(a[2]) - z[2]};
        const double se = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
        const double dot = e[0] * d[0] + e[1] * d[1] + e[2] * d[2];
        b.angles.push_back(std::acos(std::clamp(dot / (s * se), -1.0, 1.0)) * 180.0 / M_PI);
      }
    }
    b.lengths.push_back(length);
  }
  std::sort(b.steps.begin(), b.steps.end());
  std::sort(b.angles.begin(), b.angles.end());
  return b;
}

// Streamlines with a known step distribution: most steps exactly 0.5 mm,
// some 2 % off, turning angles uniform in [0, 20] degrees.
Tractogram trackerLike(size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Tractogram t;
  for (size_t s = 0; s < count; ++s) {
    const size_t n = 2 + rng() % 80;
    double p[3] = {u(rng) * 100, u(rng) * 100, u(rng) * 100};
    double d[3] = {1, 0, 0};
    std::vector<float> xyz;
    for (size_t i = 0; i < n; ++i) {
      xyz.insert(xyz.end(), {float(p[0]), float(p[1]), float(p[2])});
      const double step = u(rng) < 0.9 ? 0.5 : 0.51;
      for (int k = 0; k < 3; ++k) p[k] += step * d[k];
      // Turn by a random angle about a random axis perpendicular-ish.
      const double a = u(rng) * 20.0 * M_PI / 180.0, phi = u(rng) * 2 * M_PI;
      double q[3] = {0, std::cos(phi), std::sin(phi)};
      const double qd = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
      for (int k = 0; k < 3; ++k) q[k] -= qd * d[k];
      const double ql = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      for (int k = 0; k < 3; ++k) d[k] = std::cos(a) * d[k] + std::sin(a) * q[k] / ql;
    }
    t.addStreamline(xyz.data(), n);
  }
  return t;
}

}  // namespace

TEST(TractogramStats, matchesBruteForceStatistics) {
  const Tractogram t = trackerLike(500, 3);
  TractogramStatsAccumulator acc;
  acc.add(t);
  const TractogramStats s = acc.result();
  const BruteForce b = bruteForce(t);

  EXPECT_EQ(s.streamlines, t.streamlineCount());
  EXPECT_EQ(s.points, t.pointCount());
  EXPECT_EQ(s.segments, b.steps.size());
  EXPECT_DOUBLE_EQ(s.step_min, b.steps.front());
  EXPECT_DOUBLE_EQ(s.step_max, b.steps.back());
  const double median = b.steps[(b.steps.size() - 1) / 2];
  EXPECT_NEAR(s.step_median, median, 2e-4 * median);
  size_t within = 0;
  for (double v : b.steps) within += std::fabs(v - median) <= 0.01 * median;
  EXPECT_NEAR(s.step_within_1pct, double(within) / b.steps.size(), 1e-9);
  EXPECT_DOUBLE_EQ(s.angle_max_deg, b.angles.back());
  // Percentiles: the upper edge of the 0.001-degree bin holding the sample.
  for (const auto& [fraction, value] : {std::pair{0.5, s.angle_p50_deg}, {0.99, s.angle_p99_deg}, {0.999, s.angle_p999_deg}}) {
    const double exact = b.angles[size_t(std::ceil(fraction * b.angles.size())) - 1];
    EXPECT_GE(value, exact - 1e-9) << fraction;
    EXPECT_LE(value, exact + 0.001 + 1e-9) << fraction;
  }
  double angle_sum = 0;
  for (double a : b.angles) angle_sum += a;
  EXPECT_NEAR(s.angle_mean_deg, angle_sum / b.angles.size(), 1e-9);
  EXPECT_NEAR(s.length_min, *std::min_element(b.lengths.begin(), b.lengths.end()), 1e-9);
  EXPECT_NEAR(s.length_max, *std::max_element(b.lengths.begin(), b.lengths.end()), 1e-9);
  double sum = 0;
  for (double v : b.lengths) sum += v;
  EXPECT_NEAR(s.length_mean, sum / b.lengths.size(), 1e-9);
}

TEST(TractogramStats, chunkedAndMergedEqualsWhole) {
  const Tractogram t = trackerLike(300, 5);
  TractogramStatsAccumulator whole, a, b;
  whole.add(t);
  Tractogram first, second;
  for (size_t f = 0; f < t.streamlineCount(); ++f)
    (f < 100 ? first : second).addStreamline(t.point(t.offsets[f]), t.pointsIn(f));
  a.add(first);
  b.add(second);
  a.merge(b);
  const TractogramStats x = whole.result(), y = a.result();
  EXPECT_EQ(x.segments, y.segments);
  EXPECT_EQ(x.step_median, y.step_median);
  EXPECT_EQ(x.angle_p999_deg, y.angle_p999_deg);
  EXPECT_NEAR(x.length_mean, y.length_mean, 1e-9);
  EXPECT_EQ(x.bbox_min, y.bbox_min);
}

TEST(TractogramStats, countsDegenerateStreamlines) {
  Tractogram t;
  const float one[3] = {1, 2, 3};
  const float repeated[9] = {0, 0, 0, 0, 0, 0, 1, 0, 0};
  t.addStreamline(one, 0);
  t.addStreamline(one, 1);
  t.addStreamline(repeated, 3);
  TractogramStatsAccumulator acc;
  acc.add(t);
  const TractogramStats s = acc.result();
  EXPECT_EQ(s.empty_streamlines, 1u);
  EXPECT_EQ(s.single_point_streamlines, 1u);
  EXPECT_EQ(s.zero_length_segments, 1u);
  EXPECT_EQ(s.segments, 2u);
  EXPECT_DOUBLE_EQ(s.length_max, 1.0);
  EXPECT_EQ(s.angle_max_deg, 0.0);  // the zero-length segment has no direction
}

}  // namespace fibscope
