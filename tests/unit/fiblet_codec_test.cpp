// Fiblet codec: direction codes, shared decode arithmetic, encoder modes,
// exceptions and error figures on the brain phantom.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <map>
#include <numbers>

#include "codec/codec_error.h"
#include "codec/codec_params.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "core/error.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "shared/fiblet.h"

namespace fibscope {
namespace {

using shader::vec3;

constexpr double kDeg = std::numbers::pi / 180.0;

// A few hundred phantom streamlines at `step` mm (cached: tests reuse them).
// The default, whole-brain phantom at 0.1 mm; at other steps the named
// bundles alone, the mix the 0.05 mm targets were set on (the whole-brain
// mix there keeps the size and error bounds, but its closed-loop maximum is
// 0.53-0.58 of the open loop's: CompressCli's 0.05 mm test says more).
const Tractogram& phantom(double step) {
  static std::map<double, Tractogram> cache;
  auto it = cache.find(step);
  if (it != cache.end()) return it->second;
  PhantomOptions options;
  if (step != 0.1) applyNamedBundlesPhantomMix(options);
  options.streamlines = 300;
  options.step_mm = step;
  options.seed = 7;
  options.threads = 1;
  return cache.emplace(step, readAllStreamlines(*openPhantom(options))).first->second;
}

double angleBetween(vec3 a, vec3 b) {
  const double c = (double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z) /
                   std::sqrt((double(a.x) * a.x + double(a.y) * a.y + double(a.z) * a.z) *
                             (double(b.x) * b.x + double(b.y) * b.y + double(b.z) * b.z));
  return std::acos(std::clamp(c, -1.0, 1.0));
}

// A straight run of n points along `dir` (unit) from `start`, step mm apart.
void appendLine(std::vector<float>& xyz, const double start[3], const double dir[3], double step, size_t n) {
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) xyz.push_back(float(start[c] + dir[c] * step * double(i)));
}

struct Coded {
  CodecParams params;
  EncodedFiblets fiblets;
  EncodeReport report;
  CodecErrorStats error;
};

Coded encodeAndMeasure(const Tractogram& t, const CodecParams& params, EncodeMode mode) {
  Coded c;
  c.params = params;
  EncodeOptions options;
  options.mode = mode;
  c.fiblets = encodeTractogram(t, params, options, &c.report);
  c.error = measureCodecError(t, c.fiblets, FibletDecoder(params));
  return c;
}

uint64_t ceilFibletCount(const Tractogram& t, uint32_t n) {
  uint64_t total = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s) total += (t.pointsIn(s) + n - 1) / n;
  return total;
}

TEST(FibletLayout, recordSizesAndConstants) {
  EXPECT_EQ(shader::fibletRecordBytes(60), 72u);
  EXPECT_EQ(shader::fibletRecordBytes(32), 44u);
  EXPECT_EQ(shader::fibletRecordBytes(8), 20u);
  EXPECT_EQ(shader::kFibletInvQuantMax, 1.0f / 65535.0f);
  EXPECT_EQ(shader::fibletFlagsByte(60), 70u);
  EXPECT_EQ(shader::fibletCodeByte(59), 69u);
  EXPECT_EQ(shader::fibletCount(shader::fibletFlags(true, false, 60)), 60u);
  EXPECT_EQ(shader::fibletFlags(true, true, 1), 7u);
}

TEST(FibletArithmetic, rsqrtIsAccurateAndNeverNaN) {
  for (float x = 1e-12f; x < 1e12f; x *= 1.37f) {
    const double exact = 1.0 / std::sqrt(double(x));
    EXPECT_NEAR(shader::fibletRsqrt(x), exact, exact * 4e-7) << x;
  }
  const vec3 zero = shader::fibletNormalize(vec3(0.0f));
  EXPECT_EQ(zero, vec3(0.0f));
}

TEST(FibletDirections, everyCodeDecodesAndReencodesToItself) {
  for (double alpha_deg : {1.0, 5.0, 15.0, 22.5, 45.0, 60.0, 89.0, 90.0}) {
    for (uint32_t code = 0; code < 256; ++code) {
      const vec3 d = decodeDirection(code, alpha_deg * kDeg);
      EXPECT_EQ(encodeDirection(glm::dvec3(d.x, d.y, d.z), alpha_deg * kDeg), code) << "alpha " << alpha_deg << " code " << code;
    }
  }
}

TEST(FibletDirections, sharedOctahedralCellMatchesTheHemisphereDirection) {
  for (uint32_t code = 0; code < 256; ++code) {
    const vec3 cell = shader::fibletOctahedralCell(code);
    EXPECT_GT(cell.z, 0.06f);
    EXPECT_LT(angleBetween(cell, decodeDirection(code, std::numbers::pi / 2)), 1e-6) << code;
  }
}

TEST(FibletDirections, capMappingScalesThePolarAngleAndKeepsTheAzimuth) {
  for (double alpha_deg : {3.0, 15.0, 40.0}) {
    const double alpha = alpha_deg * kDeg;
    double widest = 0;
    for (uint32_t code = 0; code < 256; ++code) {
      const vec3 h = decodeDirection(code, std::numbers::pi / 2);
      const vec3 d = decodeDirection(code, alpha);
      const double theta_h = std::acos(double(h.z)), theta = std::acos(std::clamp(double(d.z), -1.0, 1.0));
      EXPECT_NEAR(theta, theta_h * alpha / (std::numbers::pi / 2), 1e-3 * kDeg + 2e-4);
      EXPECT_NEAR(std::atan2(d.y, d.x), std::atan2(h.y, h.x), 1e-5);
      EXPECT_LE(theta, alpha);
      widest = std::max(widest, theta);
    }
    // The outermost cell centres reach 86.2/90 of the cap.
    EXPECT_GT(widest, 0.95 * alpha);
  }
  // A direction outside the cap is clamped to its rim, not wrapped.
  const glm::dvec3 sideways(1, 0, 0.2);
  const vec3 rim = decodeDirection(encodeDirection(sideways, 10 * kDeg), 10 * kDeg);
  EXPECT_GT(std::acos(double(rim.z)), 9 * kDeg);
}

TEST(FibletDirections, constantVectorIsNeverCollinearWithACodeDirection) {
  const CodecParams defaults;
  const vec3 v(defaults.v[0], defaults.v[1], defaults.v[2]);
  double smallest = 1;
  for (double alpha_deg = 0.5; alpha_deg <= 90.0; alpha_deg += 0.5) {
    const FibletDirectionTable table = buildDirectionTable(float(alpha_deg * kDeg));
    for (const shader::vec4& e : table) {
      const vec3 d(e.x, e.y, e.z);
      const vec3 c = shader::fibletCross(d, v);
      smallest = std::min(smallest, std::sqrt(double(shader::fibletDot(c, c))));
      // The local frame is orthonormal and its forward axis is d.
      const shader::FibletTransform l = shader::fibletLocalTransform(d, v, 0.01f);
      EXPECT_NEAR(shader::fibletDot(l.c0, l.c0), 1.0f, 1e-6f);
      EXPECT_NEAR(shader::fibletDot(l.c1, l.c1), 1.0f, 1e-6f);
      EXPECT_NEAR(shader::fibletDot(l.c0, l.c1), 0.0f, 1e-6f);
      EXPECT_NEAR(shader::fibletDot(l.c0, l.c2), 0.0f, 1e-6f);
      EXPECT_NEAR(shader::fibletDot(l.c1, l.c2), 0.0f, 1e-6f);
    }
  }
  // sin(3.8 degrees): V on the local equator, codes at most 86.2 degrees off axis.
  EXPECT_GT(smallest, 0.06);
}

TEST(FibletParams, stepIsTheMedianSegmentAndAlphaComesFromTheBulkOfTurns) {
  const CodecParams p = chooseCodecParams(phantom(0.1));
  EXPECT_NEAR(p.deltaMm(), 0.1, 1e-5);
  EXPECT_GT(p.alpha, float(3 * kDeg));
  EXPECT_LE(p.alpha, float(15 * 1.1 * kDeg) + 1e-6f);
  EXPECT_EQ(p.points_per_fiblet, 60u);
  // Every point maps into [0,1]^3, with the largest extent spanning it.
  double hi = 0;
  const Tractogram& t = phantom(0.1);
  for (size_t i = 0; i < t.positions.size(); ++i) {
    const double n = (double(t.positions[i]) - p.translation[i % 3]) * p.scale;
    EXPECT_GE(n, -1e-6);
    EXPECT_LE(n, 1 + 1e-6);
    hi = std::max(hi, n);
  }
  EXPECT_NEAR(hi, 1.0, 1e-6);
}

TEST(FibletParams, nonFinitePointsAreLeftOutOfTheStatistics) {
  Tractogram t;
  const float xyz[15] = {0, 0, 0, 0.2f, 0, 0, std::nanf(""), 0, 0, 0.4f, 0, 0, 0.6f, 0, 0};
  t.addStreamline(xyz, 5);
  const CodecParams p = chooseCodecParams(t);
  EXPECT_NEAR(p.deltaMm(), 0.2, 1e-6);
  EXPECT_NEAR(p.scale, 1 / 0.6, 1e-5);
  const float inf[6] = {0, 0, 0, std::numeric_limits<float>::infinity(), 0, 0};
  t.addStreamline(inf, 2);
  EXPECT_THROW(chooseCodecParams(t), Error);
}

TEST(FibletParams, invalidParametersAreRejected) {
  CodecParams p;
  p.points_per_fiblet = 62;
  EXPECT_THROW(validateCodecParams(p), Error);
  p = {};
  p.alpha = 2.0f;
  EXPECT_THROW(validateCodecParams(p), Error);
  p = {};
  p.v = {0, 0, 1};
  EXPECT_THROW(validateCodecParams(p), Error);
  p = {};
  p.delta = std::nanf("");
  EXPECT_THROW(validateCodecParams(p), Error);
  EXPECT_THROW(chooseCodecParams(Tractogram{}), Error);
}

void checkErrorTargets(double step, double max_um, double mean_um) {
  const Tractogram& t = phantom(step);
  const CodecParams params = chooseCodecParams(t);
  const Coded closed = encodeAndMeasure(t, params, EncodeMode::ClosedLoop);
  const Coded open = encodeAndMeasure(t, params, EncodeMode::OpenLoop);
  const Coded naive = encodeAndMeasure(t, params, EncodeMode::TrueFrame);
  const double bytes = double(closed.fiblets.bytes.size() + closed.fiblets.tableBytes()) / double(t.pointCount());
  std::cout << "[fiblet " << step << " mm] points " << t.pointCount() << ", alpha " << params.alpha / kDeg
            << " deg; closed loop max " << closed.error.max_um << " um, mean " << closed.error.mean_um << " um, p99 "
            << closed.error.p99_um << " um, splits " << closed.report.splits() << " (angle "
            << closed.report.angle_splits << ", error " << closed.report.error_splits << "); open loop max "
            << open.error.max_um << " um, mean " << open.error.mean_um << " um; true-frame open loop max "
            << naive.error.max_um << " um, mean " << naive.error.mean_um << " um; " << bytes << " bytes/point\n";
  EXPECT_LE(closed.error.max_um, max_um);
  EXPECT_LE(closed.error.mean_um, mean_um);
  EXPECT_LE(closed.error.max_um, 0.5 * open.error.max_um);
  // Tracking the decoded frame stops the heading drift of the true-frame variant.
  EXPECT_LT(open.error.max_um, 0.1 * naive.error.max_um);
  EXPECT_EQ(open.fiblets.fibletCount(), naive.fiblets.fibletCount());
  EXPECT_LE(bytes, 1.30);
  EXPECT_EQ(closed.report.points, t.pointCount());
}

TEST(FibletCodec, closedLoopErrorAtPoint1MmIsWithinTargetsAndHalfTheOpenLoop) { checkErrorTargets(0.1, 10, 3); }

TEST(FibletCodec, closedLoopErrorAtPoint05MmIsWithinTargetsAndHalfTheOpenLoop) { checkErrorTargets(0.05, 10, 3); }

TEST(FibletCodec, logStepScanMatchesSequentialDecodeAndBothAreDeterministic) {
  const Tractogram& t = phantom(0.1);
  const CodecParams params = chooseCodecParams(t);
  const EncodedFiblets f = encodeTractogram(t, params);
  const FibletDecoder decoder(params);
  float seq[180], scan[180], again[180];
  double worst = 0;
  for (size_t i = 0; i < f.fibletCount(); ++i) {
    const uint32_t n = decoder.decodeSequential(f.record(i), seq);
    ASSERT_EQ(decoder.decodeScan(f.record(i), scan), n);
    for (uint32_t k = 0; k < 3 * n; ++k) worst = std::max(worst, double(std::fabs(seq[k] - scan[k])));
    ASSERT_EQ(decoder.decodeScan(f.record(i), again), n);
    ASSERT_EQ(std::memcmp(scan, again, 12 * n), 0);
    ASSERT_EQ(decoder.decodeSequential(f.record(i), again), n);
    ASSERT_EQ(std::memcmp(seq, again, 12 * n), 0);
    // Points 0 and 1 are stored, not composed: identical in both.
    ASSERT_EQ(std::memcmp(seq, scan, 12 * std::min(n, 2u)), 0);
  }
  // The normalised scene has size 1.
  EXPECT_LE(worst, 1e-6);
  EXPECT_GT(f.fibletCount(), 1000u);
}

TEST(FibletCodec, fibletCountIsCeilOfPointsOverNWithoutExceptions) {
  const Tractogram& t = phantom(0.1);
  for (uint32_t n : {8u, 32u, 60u}) {
    CodecParamOptions options;
    options.points_per_fiblet = n;
    options.alpha_deg = 20;  // above the phantom's 15-degree cap: no turn is an exception
    const CodecParams params = chooseCodecParams(t, options);
    for (EncodeMode mode : {EncodeMode::ClosedLoop, EncodeMode::OpenLoop}) {
      EncodeOptions eo;
      eo.mode = mode;
      EncodeReport report;
      const EncodedFiblets f = encodeTractogram(t, params, eo, &report);
      EXPECT_EQ(report.splits(), 0u) << "N " << n;
      EXPECT_EQ(f.fibletCount(), ceilFibletCount(t, n)) << "N " << n;
      EXPECT_EQ(f.bytes.size(), f.fibletCount() * shader::fibletRecordBytes(n));
      EXPECT_EQ(validateFiblets(f, params), "");
      if (mode == EncodeMode::ClosedLoop) {
        const CodecErrorStats e = measureCodecError(t, f, FibletDecoder(params));
        EXPECT_LE(e.max_um, 10.0) << "N " << n;
        EXPECT_LE(e.mean_um, 3.0) << "N " << n;
      }
    }
  }
}

TEST(FibletCodec, sixtyDegreeKinkSplitsTheFiberIntoAContinuationFiblet) {
  std::vector<float> xyz;
  const double start[3] = {0, 0, 0}, along_x[3] = {1, 0, 0};
  appendLine(xyz, start, along_x, 0.1, 100);
  const double corner[3] = {xyz[297] + 0.1 * 0.5, xyz[298] + 0.1 * std::sqrt(0.75), 0};
  const double turned[3] = {0.5, std::sqrt(0.75), 0};
  appendLine(xyz, corner, turned, 0.1, 100);
  Tractogram t;
  t.addStreamline(xyz.data(), 200);
  CodecParams params = chooseCodecParams(t);
  params.alpha = float(15 * kDeg);
  EncodeReport report;
  const EncodedFiblets f = encodeTractogram(t, params, {}, &report);
  EXPECT_EQ(report.angle_splits, 1u);
  EXPECT_EQ(report.step_splits, 0u);
  ASSERT_EQ(f.fibletCount(), 4u);  // 60 + 40 before the kink, 60 + 40 after
  const uint32_t flags_at = shader::fibletFlagsByte(60);
  EXPECT_EQ(f.record(0)[flags_at], shader::fibletFlags(true, false, 60));
  EXPECT_EQ(f.record(1)[flags_at], shader::fibletFlags(false, false, 40));
  EXPECT_EQ(f.record(2)[flags_at], shader::fibletFlags(false, false, 60));
  EXPECT_EQ(f.record(3)[flags_at], shader::fibletFlags(false, true, 40));
  const CodecErrorStats e = measureCodecError(t, f, FibletDecoder(params));
  EXPECT_LE(e.max_um, 10.0);
}

TEST(FibletCodec, oneAndTwoPointStreamlinesAreStoredExactlyToQuantisation) {
  Tractogram t;
  const float one[3] = {10, 20, 30};
  const float two[6] = {-40, 5, 7, -39.9f, 5.05f, 7};
  const float three[9] = {0, 0, 0, 0.1f, 0, 0, 0.2f, 0.001f, 0};
  t.addStreamline(one, 1);
  t.addStreamline(two, 2);
  t.addStreamline(nullptr, 0);
  t.addStreamline(three, 3);
  const CodecParams params = chooseCodecParams(t);
  EncodeReport report;
  const EncodedFiblets f = encodeTractogram(t, params, {}, &report);
  EXPECT_EQ(report.single_point_fibers, 1u);
  EXPECT_EQ(report.two_point_fibers, 1u);
  ASSERT_EQ(f.fibletCount(), 3u);
  EXPECT_EQ(f.record(0)[shader::fibletFlagsByte(60)], shader::fibletFlags(true, true, 1));
  EXPECT_EQ(f.record(1)[shader::fibletFlagsByte(60)], shader::fibletFlags(true, true, 2));
  EXPECT_EQ(f.fiber_first_fiblet, (std::vector<uint32_t>{0, 1, 2, 2}));
  EXPECT_EQ(f.fiber_points, (std::vector<uint32_t>{1, 2, 0, 3}));
  const Tractogram back = FibletDecoder(params).decodeAll(f);
  ASSERT_EQ(back.offsets, t.offsets);
  // Half a quantisation step per coordinate of the 70 mm box.
  const double bound = 0.5 / 65535.0 / params.scale * std::sqrt(3.0) * 1.0001;
  for (size_t i = 0; i < 3; ++i) {
    const float* a = t.point(i);
    const float* b = back.point(i);
    EXPECT_LE(std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]), bound) << i;
  }
}

TEST(FibletCodec, corruptFibletsAreReportedNotDecoded) {
  const Tractogram& t = phantom(0.1);
  const CodecParams params = chooseCodecParams(t);
  const EncodedFiblets good = encodeTractogram(t, params);
  const FibletDecoder decoder(params);
  const uint32_t flags_at = shader::fibletFlagsByte(60);
  auto expectRejected = [&](const EncodedFiblets& bad, const char* what) {
    EXPECT_NE(validateFiblets(bad, params), "") << what;
    try {
      decoder.decodeAll(bad);
      ADD_FAILURE() << what << ": no error";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos);
      EXPECT_EQ(message.rfind("fiblets: ", 0), 0u) << message;
    }
  };
  EncodedFiblets bad = good;
  bad.bytes[5 * 72 + flags_at] &= 3;  // count 0
  expectRejected(bad, "count 0");
  float xyz[180];
  EXPECT_EQ(decoder.decodeScan(bad.record(5), xyz), 0u);
  EXPECT_EQ(decoder.decodeSequential(bad.record(5), xyz), 0u);
  bad = good;
  bad.bytes[5 * 72 + flags_at] = uint8_t(bad.bytes[5 * 72 + flags_at] | 63u << 2);  // count 63 > N
  expectRejected(bad, "count 63");
  bad = good;
  bad.bytes[0 + flags_at] ^= shader::kFibletFlagBegins;
  expectRejected(bad, "begins flag");
  bad = good;
  bad.bytes.resize(bad.bytes.size() - 72);
  expectRejected(bad, "missing last record");
  bad = good;
  bad.bytes.resize(bad.bytes.size() - 1);
  expectRejected(bad, "partial record");
  bad = good;
  bad.fiber_points[3] += 1;
  expectRejected(bad, "point table");
  bad = good;
  bad.fiber_first_fiblet[2] = bad.fiber_first_fiblet[1];
  expectRejected(bad, "first-fiblet table");
}

TEST(FibletCodec, resamplingMakesStepsConstantSoOnlyTheLastSegmentIsAnException) {
  // A helix sampled at irregular steps.
  std::vector<float> xyz;
  double s = 0;
  for (int i = 0; i < 400; ++i) {
    xyz.insert(xyz.end(), {float(5 * std::cos(s / 5)), float(5 * std::sin(s / 5)), float(0.3 * s)});
    s += 0.03 + 0.05 * (i % 3);
  }
  Tractogram t;
  t.addStreamline(xyz.data(), xyz.size() / 3);
  ResampleReport rr;
  const Tractogram r = resampleToStep(t, 0.1, &rr);
  EXPECT_EQ(rr.input_points, 400u);
  EXPECT_EQ(rr.output_points, r.pointCount());
  EXPECT_GT(rr.moved_points, 100u);
  // The helix has radius 5 mm: a 0.1 mm chord is at most 0.1^2 / (8 * 5) =
  // 0.25 um from the arc, and the input polyline (steps up to 0.13 mm) is
  // itself that close to it.
  EXPECT_GT(rr.max_deviation_mm, 0.0);
  EXPECT_LT(rr.max_deviation_mm, 1e-3);
  EXPECT_LE(rr.mean_deviation_mm, rr.max_deviation_mm);
  const size_t n = r.pointCount();
  for (size_t i = 1; i + 1 < n; ++i) {
    const float* a = r.point(i - 1);
    const float* b = r.point(i);
    EXPECT_NEAR(std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]), 0.1, 1e-5) << i;
  }
  EXPECT_EQ(std::memcmp(r.point(0), t.point(0), 12), 0);
  EXPECT_EQ(std::memcmp(r.point(n - 1), t.point(399), 12), 0);
  const CodecParams params = chooseCodecParams(r);
  EncodeReport report;
  const EncodedFiblets f = encodeTractogram(r, params, {}, &report);
  EXPECT_LE(report.step_splits, 1u);
  EXPECT_EQ(report.angle_splits, 0u);
  EXPECT_LE(measureCodecError(r, f, FibletDecoder(params)).max_um, 10.0);
  EXPECT_THROW(resampleToStep(t, 0), Error);
  Tractogram far;
  const float jump[6] = {0, 0, 0, 1e30f, 0, 0};
  far.addStreamline(jump, 2);
  EXPECT_THROW(resampleToStep(far, 0.1), Error);
  Tractogram nan;
  const float bad[6] = {0, 0, 0, std::nanf(""), 0, 0};
  nan.addStreamline(bad, 2);
  EXPECT_THROW(resampleToStep(nan, 0.1), Error);
  // A polyline with a corner: the chord across the corner is measured.
  const float corner[9] = {0, 0, 0, 1, 0, 0, 1, 1, 0};
  Tractogram bent;
  bent.addStreamline(corner, 3);
  ResampleReport cr;
  resampleToStep(bent, 0.3, &cr);
  // Points at 0.3, 0.6, 0.9 on x, then the chord from (0.9, 0, 0) to where the
  // 0.3 sphere meets x = 1 (y = sqrt(0.09 - 0.01)) passes the corner at
  // distance 0.1 * y / 0.3.
  const double y = std::sqrt(0.08);
  EXPECT_NEAR(cr.max_deviation_mm, 0.1 * y / 0.3, 1e-6);
}

TEST(FibletCodec, pointsOutsideTheBoxOrNotFiniteAreClampedAndCounted) {
  Tractogram t;
  const float inside[9] = {0, 0, 0, 0.1f, 0, 0, 0.2f, 0, 0};
  t.addStreamline(inside, 3);
  const CodecParams params = chooseCodecParams(t);
  Tractogram bad;
  const float nan = std::nanf("");
  const float outside[15] = {nan, 0, 0, 0.1f, nan, 0, 500, 0, 0, -1e30f, 0, 0, 0.3f, 0, 0};
  bad.addStreamline(outside, 5);
  for (EncodeMode mode : {EncodeMode::ClosedLoop, EncodeMode::TrueFrame, EncodeMode::OpenLoop}) {
    EncodeOptions options;
    options.mode = mode;
    EncodeReport report;
    const EncodedFiblets f = encodeTractogram(bad, params, options, &report);
    EXPECT_GE(report.clamped_points, 1u);
    EXPECT_EQ(validateFiblets(f, params), "");
    EXPECT_EQ(FibletDecoder(params).decodeAll(f).pointCount(), 5u);
  }
}

TEST(FibletCodec, streamedChunksEncodeExactlyAsOneCall) {
  const Tractogram& t = phantom(0.1);
  const CodecParams params = chooseCodecParams(t);
  const EncodedFiblets whole = encodeTractogram(t, params);
  // A streaming caller: encode 37 streamlines at a time, move the records
  // and tables out, advance fiblet_base.
  FibletEncoder encoder(params);
  EncodedFiblets chunk, joined;
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    encoder.encodeStreamline(t.point(t.offsets[s]), t.pointsIn(s), chunk);
    if (s % 37 == 36 || s + 1 == t.streamlineCount()) {
      EXPECT_EQ(validateFiblets(chunk, params), "");
      joined.bytes.insert(joined.bytes.end(), chunk.bytes.begin(), chunk.bytes.end());
      joined.fiber_first_fiblet.insert(joined.fiber_first_fiblet.end(), chunk.fiber_first_fiblet.begin(),
                                       chunk.fiber_first_fiblet.end());
      joined.fiber_points.insert(joined.fiber_points.end(), chunk.fiber_points.begin(), chunk.fiber_points.end());
      chunk.fiblet_base += chunk.fibletCount();
      chunk.bytes.clear();
      chunk.fiber_first_fiblet.clear();
      chunk.fiber_points.clear();
    }
  }
  EXPECT_EQ(joined.bytes, whole.bytes);
  EXPECT_EQ(joined.fiber_first_fiblet, whole.fiber_first_fiblet);
  EXPECT_EQ(joined.fiber_points, whole.fiber_points);
  EXPECT_EQ(encoder.report().fiblets, whole.fibletCount());
}

TEST(FibletCodec, errorMeterPercentileAndMean) {
  CodecErrorMeter meter;
  for (int i = 1; i <= 1000; ++i) meter.add(i * 0.01);
  const CodecErrorStats s = meter.stats();
  EXPECT_EQ(s.points, 1000u);
  EXPECT_NEAR(s.max_um, 10.0, 1e-12);
  EXPECT_NEAR(s.mean_um, 5.005, 1e-9);
  EXPECT_NEAR(s.p99_um, 9.9, 0.011);
}

}  // namespace
}  // namespace fibscope
