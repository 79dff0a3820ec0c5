// The brain-like phantom: determinism, tracker statistics (exact steps,
// bounded turns, lengths), the ellipsoid, the bundles, and the statistics
// helper against a brute-force computation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/fiber_density.h"
#include "phantom/phantom.h"
#include "phantom/phantom_stats.h"

namespace fibscope {
namespace {

Tractogram readPhantom(const PhantomOptions& options, size_t max_points = size_t(1) << 20,
                       TractogramHeader* header = nullptr) {
  auto reader = openPhantom(options);
  if (header) *header = reader->header();
  Tractogram all;
  Tractogram chunk;
  while (reader->read(chunk, max_points)) {
    EXPECT_EQ(chunk.validate(), "");
    EXPECT_GE(chunk.streamlineCount(), 1u);
    // A chunk holds at most max_points points unless one streamline alone is longer.
    if (chunk.streamlineCount() > 1) {
      EXPECT_LE(chunk.pointCount(), max_points);
    }
    all.append(chunk);
  }
  return all;
}

PhantomOptions smallOptions(uint64_t streamlines, unsigned threads = 2) {
  PhantomOptions o;
  o.streamlines = streamlines;
  o.threads = threads;
  return o;
}

PhantomOptions namedBundles(uint64_t streamlines) {
  PhantomOptions o = smallOptions(streamlines);
  applyNamedBundlesPhantomMix(o);
  return o;
}

// Independent geometry, in long double with acos (the library uses atan2 in
// double), so the two computations share no formula.
long double segmentLength(const float* a, const float* b) {
  const long double dx = (long double)b[0] - a[0], dy = (long double)b[1] - a[1], dz = (long double)b[2] - a[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

long double turnDegrees(const float* a, const float* b, const float* c) {
  const long double u[3] = {(long double)b[0] - a[0], (long double)b[1] - a[1], (long double)b[2] - a[2]};
  const long double v[3] = {(long double)c[0] - b[0], (long double)c[1] - b[1], (long double)c[2] - b[2]};
  const long double nu = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  const long double nv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  long double cosine = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (nu * nv);
  cosine = std::clamp(cosine, -1.0L, 1.0L);
  return std::acos(cosine) * 180.0L / 3.14159265358979323846264338327950288L;
}

long double streamlineLength(const Tractogram& t, size_t s) {
  long double length = 0;
  for (size_t k = t.offsets[s] + 1; k < t.offsets[s + 1]; ++k) length += segmentLength(t.point(k - 1), t.point(k));
  return length;
}

double meanLength(const Tractogram& t) {
  long double sum = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s) sum += streamlineLength(t, s);
  return double(sum / t.streamlineCount());
}

TEST(Phantom, readerDeclaresFormatBundleArrayAndOptions) {
  PhantomOptions o = smallOptions(50);
  o.seed = 77;
  TractogramHeader header;
  const Tractogram t = readPhantom(o, size_t(1) << 20, &header);
  EXPECT_EQ(header.format, "phantom");
  EXPECT_EQ(header.declared_streamlines, 50);
  ASSERT_EQ(header.per_streamline.size(), 1u);
  EXPECT_EQ(header.per_streamline[0].name, "bundle");
  EXPECT_EQ(header.per_streamline[0].dtype, "uint8");
  EXPECT_TRUE(header.per_point.empty());
  EXPECT_TRUE(header.space.known);
  EXPECT_EQ(header.property("step_size"), "0.1");
  EXPECT_EQ(header.property("max_angle"), "15");
  EXPECT_EQ(header.property("phantom_seed"), "77");
  EXPECT_EQ(header.property("phantom_bundles").substr(0, 25), "corpus_callosum,cst_left,");
  ASSERT_EQ(t.per_streamline.size(), 1u);
  EXPECT_EQ(t.per_streamline[0].values.size(), 50u);
}

TEST(Phantom, streamlineCountIsExact) {
  for (uint64_t n : {0, 1, 7, 321}) {
    const Tractogram t = readPhantom(smallOptions(n), 5000);
    EXPECT_EQ(t.streamlineCount(), n);
    EXPECT_EQ(t.validate(), "");
  }
}

TEST(Phantom, sameSeedGivesSamePointsOtherSeedDoesNot) {
  PhantomOptions o = smallOptions(300);
  o.seed = 5;
  const Tractogram a = readPhantom(o);
  const Tractogram b = readPhantom(o);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.per_streamline[0].values, b.per_streamline[0].values);
  o.seed = 6;
  const Tractogram c = readPhantom(o);
  EXPECT_NE(a.positions, c.positions);
}

TEST(Phantom, outputIsIndependentOfThreadsAndChunkSize) {
  const Tractogram reference = readPhantom(smallOptions(300, 1), size_t(1) << 20);
  struct Case {
    unsigned threads;
    size_t max_points;
  };
  for (const Case c : {Case{2, 1}, Case{2, 777}, Case{3, 50000}, Case{8, 123456}, Case{0, size_t(1) << 22}}) {
    SCOPED_TRACE("threads " + std::to_string(c.threads) + ", max_points " + std::to_string(c.max_points));
    const Tractogram t = readPhantom(smallOptions(300, c.threads), c.max_points);
    EXPECT_EQ(t.positions, reference.positions);
    EXPECT_EQ(t.offsets, reference.offsets);
    EXPECT_EQ(t.per_streamline[0].values, reference.per_streamline[0].values);
  }
}

TEST(Phantom, streamlineDependsOnlyOnSeedAndIndex) {
  const PhantomOptions o = smallOptions(400);
  const Tractogram all = readPhantom(o);
  // A generator for a phantom of another size, asked for single indices out
  // of order, gives the same streamlines.
  PhantomOptions other = o;
  other.streamlines = 3;
  const PhantomGenerator generator(other);
  PhantomScratch scratch;
  for (uint64_t i : {399, 0, 123, 7, 250}) {
    std::vector<float> xyz;
    const PhantomBundle bundle = generator.generate(i, xyz, scratch);
    const std::vector<float> expected(all.positions.begin() + ptrdiff_t(3 * all.offsets[i]),
                                      all.positions.begin() + ptrdiff_t(3 * all.offsets[i + 1]));
    EXPECT_EQ(xyz, expected) << "streamline " << i;
    EXPECT_EQ(float(uint8_t(bundle)), all.per_streamline[0].values[i]);
  }
}

TEST(Phantom, everySegmentHasTheStepLength) {
  for (double step : {0.05, 0.1, 0.5}) {
    SCOPED_TRACE("step " + std::to_string(step));
    PhantomOptions o = smallOptions(step < 0.1 ? 400 : 800);
    o.step_mm = step;
    const Tractogram t = readPhantom(o);
    long double worst = 0;
    for (size_t s = 0; s < t.streamlineCount(); ++s)
      for (size_t k = t.offsets[s] + 1; k < t.offsets[s + 1]; ++k)
        worst = std::max(worst, std::abs(segmentLength(t.point(k - 1), t.point(k)) / step - 1.0L));
    EXPECT_LE(double(worst), 1e-4);
    EXPECT_GT(t.pointCount(), t.streamlineCount() * size_t(20.0 / step));  // the step really was used
  }
}

TEST(Phantom, turnsNeverExceedTheMaximumAngleAndMostAreSmall) {
  struct Case {
    double step, max_angle;
    bool cap_reached;  // whether the jitter must hit the cap in this configuration
  };
  for (const Case c : {Case{0.1, 15.0, false}, Case{0.5, 6.0, true}, Case{0.05, 2.0, true}}) {
    SCOPED_TRACE("step " + std::to_string(c.step) + ", max angle " + std::to_string(c.max_angle));
    PhantomOptions o = smallOptions(400);
    o.step_mm = c.step;
    o.max_angle_deg = c.max_angle;
    const Tractogram t = readPhantom(o);
    long double worst = 0, sum = 0;
    size_t turns = 0, above_half = 0;
    for (size_t s = 0; s < t.streamlineCount(); ++s)
      for (size_t k = t.offsets[s] + 2; k < t.offsets[s + 1]; ++k) {
        const long double a = turnDegrees(t.point(k - 2), t.point(k - 1), t.point(k));
        worst = std::max(worst, a);
        sum += a;
        ++turns;
        if (a > 0.5L * c.max_angle) ++above_half;
      }
    ASSERT_GT(turns, 0u);
    EXPECT_LE(double(worst), c.max_angle + 1e-7);
    if (c.cap_reached) {
      EXPECT_GT(double(worst), 0.99 * c.max_angle);
    } else {
      // Probabilistic-tracker-like: a jitter of a few degrees, the cap far out in the tail.
      EXPECT_LT(double(sum / turns), c.max_angle / 3);
      EXPECT_LT(double(above_half) / double(turns), 0.01);
    }
  }
}

TEST(Phantom, zeroJitterGivesSmoothFibers) {
  PhantomOptions o = smallOptions(200);
  o.jitter = 0;
  const Tractogram t = readPhantom(o);
  long double worst = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s)
    for (size_t k = t.offsets[s] + 2; k < t.offsets[s + 1]; ++k)
      worst = std::max(worst, turnDegrees(t.point(k - 2), t.point(k - 1), t.point(k)));
  EXPECT_LT(double(worst), 3.0);  // only the bundles' own curvature and the pursuit's corrections
}

TEST(Phantom, lengthsStayWithinBounds) {
  struct Case {
    double min, max, step;
  };
  for (const Case c : {Case{20, 250, 0.1}, Case{40, 60, 0.1}, Case{0, 30, 0.5}, Case{100, 120, 0.2}}) {
    SCOPED_TRACE("lengths " + std::to_string(c.min) + " to " + std::to_string(c.max));
    PhantomOptions o = smallOptions(500);
    o.min_length_mm = c.min;
    o.max_length_mm = c.max;
    o.step_mm = c.step;
    const Tractogram t = readPhantom(o);
    ASSERT_EQ(t.streamlineCount(), 500u);
    long double shortest = 1e9, longest = 0;
    for (size_t s = 0; s < t.streamlineCount(); ++s) {
      const long double length = streamlineLength(t, s);
      shortest = std::min(shortest, length);
      longest = std::max(longest, length);
    }
    EXPECT_GE(double(shortest), c.min * (1 - 1e-4));
    EXPECT_LE(double(longest), c.max * (1 + 1e-4));
  }
}

TEST(Phantom, defaultLengthsLookLikeWholeBrainTracking) {
  const Tractogram t = readPhantom(smallOptions(1500));
  size_t short_ones = 0, long_ones = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    const long double length = streamlineLength(t, s);
    if (length < 40) ++short_ones;
    if (length > 150) ++long_ones;
  }
  // Between the fiblets paper's 500 k iFOD1 set (0.43 G segments at 0.1 mm:
  // 86 mm per fiber) and MRtrix3 iFOD1 on make_tckgen_250mb.sh's field
  // (136 mm; docs/BENCHMARKS.md, "Phantom density").
  const double mean = meanLength(t);
  EXPECT_GT(mean, 95.0);
  EXPECT_LT(mean, 120.0);
  // Under 40 mm: U-fibers and cut-short streamlines, 3 % (iFOD1: 2 %);
  // over 150 mm: whole arcuate, IFOF and white-matter arcs, 11 % (iFOD1: 45 %).
  EXPECT_GT(short_ones, 25u);
  EXPECT_GT(long_ones, 75u);
  // The named bundles alone: the paper's 86 mm.
  const double named = meanLength(readPhantom(namedBundles(1500)));
  EXPECT_GT(named, 80.0);
  EXPECT_LT(named, 95.0);
}

TEST(Phantom, pointsStayInsideTheEllipsoid) {
  PhantomOptions o = smallOptions(2000);
  o.step_mm = 0.2;
  const Tractogram t = readPhantom(o);
  const double a = kPhantomSemiAxesMm[0], b = kPhantomSemiAxesMm[1], c = kPhantomSemiAxesMm[2];
  double worst = 0;
  float extent[3] = {0, 0, 0};
  for (size_t i = 0; i < t.pointCount(); ++i) {
    const float* p = t.point(i);
    worst = std::max(worst, double(p[0]) * p[0] / (a * a) + double(p[1]) * p[1] / (b * b) + double(p[2]) * p[2] / (c * c));
    for (int k = 0; k < 3; ++k) extent[k] = std::max(extent[k], std::abs(p[k]));
  }
  EXPECT_LE(worst, 1.0 + 1e-12);
  EXPECT_GT(worst, 0.95);  // fibers do reach the cortex
  // Brain-sized: the bundles span most of each axis.
  EXPECT_GT(extent[0], 0.8 * a);
  EXPECT_GT(extent[1], 0.8 * b);
  EXPECT_GT(extent[2], 0.8 * c);
}

TEST(Phantom, everyBundleIsPresentAndOnItsSide) {
  const Tractogram t = readPhantom(namedBundles(2000));
  std::vector<size_t> count(kPhantomBundleCount, 0), crossing(kPhantomBundleCount, 0);
  std::vector<size_t> wrong_side(kPhantomBundleCount, 0);
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    const auto bundle = size_t(t.per_streamline[0].values[s]);
    ASSERT_LT(bundle, kPhantomBundleCount);
    ++count[bundle];
    float lo = 1e9f, hi = -1e9f;
    for (size_t k = t.offsets[s]; k < t.offsets[s + 1]; ++k) {
      lo = std::min(lo, t.point(k)[0]);
      hi = std::max(hi, t.point(k)[0]);
    }
    if (lo < -10 && hi > 10) ++crossing[bundle];
    const std::string_view name = phantomBundleNames()[bundle];
    // RAS+: left is negative x.
    if (name.ends_with("_left") && hi > 0) ++wrong_side[bundle];
    if (name.ends_with("_right") && lo < 0) ++wrong_side[bundle];
  }
  for (size_t b = 0; b < kPhantomBundleCount; ++b) {
    SCOPED_TRACE(std::string(phantomBundleNames()[b]));
    if (namedBundlePhantomWeights()[b] == 0) {
      EXPECT_EQ(count[b], 0u);  // the white-matter families: only in the whole-brain mix
      continue;
    }
    EXPECT_GT(count[b], 40u);
    EXPECT_EQ(wrong_side[b], 0u);
  }
  // The corpus callosum connects the hemispheres: most of its fibers cross.
  const size_t cc = size_t(PhantomBundle::CorpusCallosum);
  EXPECT_GT(crossing[cc], count[cc] / 2);
  EXPECT_EQ(crossing[size_t(PhantomBundle::CstLeft)], 0u);
}

// The default, whole-brain mix fills the brain as whole-brain tracking
// does: its white-matter families spread thinly over most of the volume,
// where the named bundles alone pack as many fibers into a fraction of it;
// fatter bundles stay on their side; each family runs along its own axis.
TEST(Phantom, wholeBrainMixFillsTheBrainAlongTheFamiliesAxes) {
  const Tractogram all = readPhantom(smallOptions(3000));
  FiberDensityAccumulator spread(2.0), packed(2.0);
  spread.add(all);
  packed.add(readPhantom(namedBundles(3000)));
  const FiberDensity d = spread.result(), b = packed.result();
  EXPECT_GT(d.occupied_cm3, 2.0 * b.occupied_cm3);
  EXPECT_LT(d.mean, 0.5 * b.mean);
  // Most of the brain's volume holds some fiber (the ellipsoid is 1496 cm3).
  EXPECT_GT(d.occupied_cm3, 0.55 * 4.0 / 3.0 * 3.14159265 * 70 * 85 * 60 / 1000);

  const size_t first_family = size_t(PhantomBundle::WhiteMatterCommissural);
  double sums[3][3] = {};
  std::vector<size_t> count(kPhantomBundleCount, 0);
  for (size_t s = 0; s < all.streamlineCount(); ++s) {
    const size_t bundle = size_t(all.per_streamline[0].values[s]);
    ++count[bundle];
    const std::string_view name = phantomBundleNames()[bundle];
    float lo = 1e9f, hi = -1e9f;
    for (size_t k = all.offsets[s]; k < all.offsets[s + 1]; ++k) {
      lo = std::min(lo, all.point(k)[0]);
      hi = std::max(hi, all.point(k)[0]);
    }
    EXPECT_FALSE(name.ends_with("_left") && hi > 0) << name;
    EXPECT_FALSE(name.ends_with("_right") && lo < 0) << name;
    if (bundle < first_family) continue;
    // Mean |direction| per family: commissural fibers run left-right (x)
    // where they cross the midline, association fibers front-back (y),
    // projection fibers bottom-top (z).
    const size_t family = bundle - first_family;
    for (size_t k = all.offsets[s] + 1; k < all.offsets[s + 1]; ++k) {
      const float* p = all.point(k - 1);
      const float* q = all.point(k);
      if (family == 0 && std::abs(p[0]) > 10) continue;
      for (int c = 0; c < 3; ++c) sums[family][c] += std::abs(double(q[c]) - p[c]);
    }
  }
  for (size_t family = 0; family < 3; ++family) {
    SCOPED_TRACE("family " + std::to_string(family));
    EXPECT_GT(count[first_family + family], 600u);  // 30 % each of 3000 (weights 2.1, 2.1, 1.8 of 6.9)
    for (size_t c = 0; c < 3; ++c)
      if (c != family) EXPECT_GT(sums[family][family], 1.5 * sums[family][c]);
  }
}

TEST(Phantom, bundleWeightsSelectTheMix) {
  PhantomOptions o = smallOptions(300);
  o.bundle_weights.assign(kPhantomBundleCount, 0.0);
  o.bundle_weights[size_t(PhantomBundle::ArcuateRight)] = 1.0;
  const Tractogram t = readPhantom(o);
  for (float b : t.per_streamline[0].values) ASSERT_EQ(b, float(uint8_t(PhantomBundle::ArcuateRight)));

  const std::vector<double> mix = parsePhantomBundleMix("corpus_callosum=2, u_fibers=0");
  ASSERT_EQ(mix.size(), kPhantomBundleCount);
  EXPECT_EQ(mix[size_t(PhantomBundle::CorpusCallosum)], 2.0);
  EXPECT_EQ(mix[size_t(PhantomBundle::UFibers)], 0.0);
  EXPECT_EQ(mix[size_t(PhantomBundle::CstLeft)], defaultPhantomBundleWeights()[size_t(PhantomBundle::CstLeft)]);
  EXPECT_EQ(phantomBundleIndex("cingulum_right"), int(PhantomBundle::CingulumRight));
  EXPECT_EQ(phantomBundleIndex("fornix"), -1);
}

TEST(Phantom, badOptionsAreOneLineErrors) {
  auto expectError = [](const PhantomOptions& o, const std::string& needle) {
    try {
      openPhantom(o);
      ADD_FAILURE() << "no error for " << needle;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(needle), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  PhantomOptions o;
  o.step_mm = 0;
  expectError(o, "step_mm");
  o = {};
  o.step_mm = std::nan("");
  expectError(o, "step_mm");
  o = {};
  o.max_angle_deg = 0.1;
  expectError(o, "max_angle_deg");
  o = {};
  o.min_length_mm = 300;
  expectError(o, "min_length_mm");
  o = {};
  o.max_length_mm = 10;
  expectError(o, "max_length_mm");
  o = {};
  o.min_length_mm = 20.05;
  o.max_length_mm = 20.09;
  expectError(o, "whole number");
  o = {};
  o.bundle_weights = {1, 2};
  expectError(o, "bundle_weights");
  o.bundle_weights.assign(kPhantomBundleCount, 0.0);
  expectError(o, "all 0");
  o.bundle_weights[size_t(PhantomBundle::ArcuateRight)] = -1;
  expectError(o, "arcuate_right");
  EXPECT_THROW(parsePhantomBundleMix("fornix=1"), Error);
  EXPECT_THROW(parsePhantomBundleMix("cst_left"), Error);
  EXPECT_THROW(parsePhantomBundleMix("cst_left=abc"), Error);
  EXPECT_THROW(parsePhantomBundleMix("cst_left=-1"), Error);
}

TEST(Phantom, fallbackFiberKeepsTheGuarantees) {
  // U-fibers are 20-45 mm long: with a 120 mm minimum every drawn fiber is
  // rejected and the straight fallback is used.
  PhantomOptions o = smallOptions(5);
  o.bundle_weights.assign(kPhantomBundleCount, 0.0);
  o.bundle_weights[size_t(PhantomBundle::UFibers)] = 1.0;
  o.min_length_mm = 120;
  o.step_mm = 0.05;
  const PhantomGenerator generator(o);
  PhantomScratch scratch;
  std::vector<float> xyz;
  unsigned retries = 0;
  generator.generate(0, xyz, scratch, &retries);
  EXPECT_EQ(retries, kPhantomMaxRetries);
  const Tractogram t = readPhantom(o);
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    EXPECT_GE(double(streamlineLength(t, s)), 120.0 * (1 - 1e-4));
    for (size_t k = t.offsets[s] + 1; k < t.offsets[s + 1]; ++k)
      ASSERT_NEAR(double(segmentLength(t.point(k - 1), t.point(k))), 0.05, 0.05 * 1e-4);
  }
}

TEST(Phantom, retriesAreRareWithDefaults) {
  const PhantomGenerator generator(smallOptions(1));
  PhantomScratch scratch;
  std::vector<float> xyz;
  size_t retried = 0;
  for (uint64_t i = 0; i < 1000; ++i) {
    unsigned retries = 0;
    xyz.clear();
    generator.generate(i, xyz, scratch, &retries);
    ASSERT_LT(retries, kPhantomMaxRetries);
    if (retries > 0) ++retried;
  }
  EXPECT_LT(retried, 30u);  // about 1% leave the brain before 20 mm and are redrawn
}

TEST(Phantom, estimateMatchesBruteForce) {
  PhantomOptions o = smallOptions(1000);
  o.seed = 11;
  const Tractogram t = readPhantom(o);
  const PhantomEstimate e = estimatePhantom(o, 1000);

  uint64_t points = t.pointCount(), segments = 0;
  long double length_sum = 0, shortest = 1e9, longest = 0, turn_sum = 0, turn_max = 0;
  long double segment_min = 1e9, segment_max = 0;
  std::vector<long double> turns;
  std::vector<uint64_t> bundles(kPhantomBundleCount, 0);
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    ++bundles[size_t(t.per_streamline[0].values[s])];
    long double length = 0;
    for (size_t k = t.offsets[s] + 1; k < t.offsets[s + 1]; ++k) {
      const long double segment = segmentLength(t.point(k - 1), t.point(k));
      length += segment;
      segment_min = std::min(segment_min, segment);
      segment_max = std::max(segment_max, segment);
      ++segments;
      if (k >= t.offsets[s] + 2) {
        const long double turn = turnDegrees(t.point(k - 2), t.point(k - 1), t.point(k));
        turns.push_back(turn);
        turn_sum += turn;
        turn_max = std::max(turn_max, turn);
      }
    }
    length_sum += length;
    shortest = std::min(shortest, length);
    longest = std::max(longest, length);
  }
  std::sort(turns.begin(), turns.end());
  const long double p99 = turns[size_t(std::ceil(0.99 * double(turns.size()))) - 1];

  EXPECT_EQ(e.sampled_streamlines, 1000u);
  EXPECT_EQ(e.sampled_points, points);
  EXPECT_EQ(e.sampled_segments, segments);
  EXPECT_EQ(e.projected_points, points);
  EXPECT_EQ(e.projected_segments, segments);
  EXPECT_NEAR(e.length_mean_mm, double(length_sum / 1000), 1e-9);
  EXPECT_NEAR(e.length_min_mm, double(shortest), 1e-9);
  EXPECT_NEAR(e.length_max_mm, double(longest), 1e-9);
  EXPECT_NEAR(e.segment_min_mm, double(segment_min), 1e-12);
  EXPECT_NEAR(e.segment_max_mm, double(segment_max), 1e-12);
  EXPECT_NEAR(e.turn_mean_deg, double(turn_sum / turns.size()), 1e-6);
  EXPECT_NEAR(e.turn_max_deg, double(turn_max), 1e-6);
  // Histogram percentile: the upper edge of the 0.01-degree bin holding it.
  EXPECT_GE(e.turn_p99_deg, double(p99) - 1e-6);
  EXPECT_LE(e.turn_p99_deg, double(p99) + 0.01 + 1e-6);
  for (size_t b = 0; b < kPhantomBundleCount; ++b) EXPECT_EQ(e.bundle_streamlines[b], bundles[b]);

  // A sample of a larger phantom projects by the mean points per streamline.
  o.streamlines = 150000;
  const PhantomEstimate projected = estimatePhantom(o, 1000);
  EXPECT_EQ(projected.sampled_points, points);
  EXPECT_EQ(projected.projected_points, uint64_t(std::llround(double(points) * 150.0)));
  EXPECT_EQ(projected.projected_segments, projected.projected_points - 150000);
}

}  // namespace
}  // namespace fibscope
