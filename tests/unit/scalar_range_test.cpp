// Per-fiber scalars as a criterion (select/scalar_range.h, FiberFilter's
// scalar ranges): the spec's grammar and its one-line errors, the bounds
// decided in float exactly as the double bounds decide, NaN dropped, the
// arrays found in a file's list or named as missing, and runFilter keeping
// what a selection computed here from the arrays keeps.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "select/fiber_filter.h"
#include "select/filter_run.h"
#include "select/roi_set.h"
#include "select/scalar_range.h"
#include "test_support.h"

namespace fibscope {
namespace {

TEST(ScalarRange, specsParseWithOpenEndsAndComponents) {
  const ScalarRange a = parseScalarRange("fa_mean:0.3:");
  EXPECT_EQ(a.name, "fa_mean");
  EXPECT_EQ(a.component, 0u);
  EXPECT_EQ(a.min, 0.3);
  EXPECT_TRUE(std::isnan(a.max));
  const ScalarRange b = parseScalarRange("rgb[2]::128.5");
  EXPECT_EQ(b.name, "rgb");
  EXPECT_EQ(b.component, 2u);
  EXPECT_TRUE(std::isnan(b.min));
  EXPECT_EQ(b.max, 128.5);
  const ScalarRange c = parseScalarRange("a:b:-1:2e3");  // the last two colons split it
  EXPECT_EQ(c.name, "a:b");
  EXPECT_EQ(c.min, -1);
  EXPECT_EQ(c.max, 2000);
  // A name ending in "[K]" itself (an array named "t[2]"): its component 0
  // is written out, or the spec would read back as component 2 of "t".
  const ScalarRange d = parseScalarRange("t[2][0]:0:1");
  EXPECT_EQ(d.name, "t[2]");
  EXPECT_EQ(d.component, 0u);
  EXPECT_EQ(scalarRangeSpec(d), "t[2][0]:0:1");
  for (const ScalarRange& r : {a, b, c, d}) {
    const ScalarRange again = parseScalarRange(scalarRangeSpec(r));
    EXPECT_EQ(again.name, r.name);  // (open ends are NaN: no operator== on the whole)
    EXPECT_EQ(again.component, r.component);
    EXPECT_EQ(scalarRangeSpec(again), scalarRangeSpec(r));
  }
  EXPECT_EQ(scalarRangeOutside(a), "fa_mean outside [0.3, inf]");
  EXPECT_EQ(scalarRangeOutside(b), "rgb[2] outside [-inf, 128.5]");
}

TEST(ScalarRange, badSpecsAreOneLineErrors) {
  for (const char* spec : {"fa:x:1", "fa:2:1", "fa", "fa:1", ":1:2", "fa[x]:1:2", "fa[]:1:2", "fa]:1:2", "fa:1:inf",
                           "fa:nan:", "fa:1:2 "}) {
    SCOPED_TRACE(spec);
    const std::string e = test::errorOf([&] { parseScalarRange(spec); });
    EXPECT_FALSE(e.empty());
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_NE(e.find(std::string("\"") + spec + "\""), std::string::npos) << e;
  }
  EXPECT_NE(test::errorOf([] { parseScalarRange("fa:2:1"); }).find("MIN 2 is above MAX 1"), std::string::npos);
}

// For bounds that are not floats, the float test decides as the double
// test would: v is kept exactly when min <= double(v) <= max.
TEST(ScalarRange, floatBoundsDecideAsTheDoubleBounds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 200; ++trial) {
    double lo = u(rng), hi = u(rng);
    if (lo > hi) std::swap(lo, hi);
    FilterCriteria c;
    c.scalar_ranges = {ScalarRange{"v", 0, lo, hi}};
    const FiberFilter filter(c);
    // Values next to both bounds, on either side.
    for (double bound : {lo, hi}) {
      const float f = float(bound);
      for (float v : {std::nextafter(f, -INFINITY), f, std::nextafter(f, INFINITY)}) {
        const bool want = lo <= double(v) && double(v) <= hi;
        EXPECT_EQ(filter.scalarOutside(std::span(&v, 1)) < 0, want) << lo << " " << hi << " " << v;
      }
    }
  }
}

TEST(ScalarRange, boundsBeyondAFloatsRangeDecideAsTheDoubles) {
  const float big = std::numeric_limits<float>::max();
  for (const auto& [lo, hi] : {std::pair{-1e300, 1e300}, std::pair{1e300, 2e300}, std::pair{-2e300, -1e300}}) {
    FilterCriteria c;
    c.scalar_ranges = {ScalarRange{"v", 0, lo, hi}};
    const FiberFilter filter(c);
    for (float v : {-INFINITY, -big, 0.0f, big, INFINITY}) {
      const bool want = lo <= double(v) && double(v) <= hi;
      EXPECT_EQ(filter.scalarOutside(std::span(&v, 1)) < 0, want) << lo << " " << hi << " " << v;
    }
  }
}

TEST(ScalarRange, nanValuesAreDroppedAndOpenEndsKeepInfinities) {
  FilterCriteria c;
  c.scalar_ranges = {ScalarRange{"a", 0, NAN, NAN}, ScalarRange{"b", 0, 1.0, NAN}};
  const FiberFilter filter(c);
  const float xyz[6] = {0, 0, 0, 1, 0, 0};
  auto verdict = [&](float a, float b) {
    const float v[2] = {a, b};
    return filter.evaluate(xyz, 2, std::span<const float>(v, 2));
  };
  EXPECT_TRUE(verdict(-INFINITY, INFINITY).kept());
  EXPECT_TRUE(verdict(0, 1).kept());
  const FilterVerdict nan_a = verdict(NAN, 5);
  EXPECT_EQ(nan_a.reason, FilterReason::Scalar);
  EXPECT_EQ(nan_a.region, 0u);
  const FilterVerdict low_b = verdict(0, 0.999f);
  EXPECT_EQ(low_b.reason, FilterReason::Scalar);
  EXPECT_EQ(low_b.region, 1u);
  EXPECT_EQ(verdict(0, NAN).reason, FilterReason::Scalar);
  EXPECT_FALSE(c.empty());
  FilterCriteria bad;
  bad.scalar_ranges = {ScalarRange{"a", 0, 2, 1}};
  EXPECT_NE(test::errorOf([&] { FiberFilter f(bad); }).find("above"), std::string::npos);
}

TEST(ScalarRange, missingArraysNameTheFileAndListItsArrays) {
  const std::vector<DataArray> arrays = {{"weight", 1, "float32", {}}, {"rgb", 3, "float32", {}}};
  const std::vector<ScalarRange> ok = {parseScalarRange("rgb[2]:0:1"), parseScalarRange("weight::1")};
  const std::vector<ScalarColumn> columns = resolveScalarColumns(ok, arrays, "in.trx");
  ASSERT_EQ(columns.size(), 2u);
  EXPECT_EQ(columns[0].array, 1u);
  EXPECT_EQ(columns[0].component, 2u);
  EXPECT_EQ(columns[1].array, 0u);
  const std::vector<ScalarRange> missing = {parseScalarRange("fa:0.3:")};
  const std::string e = test::errorOf([&] { resolveScalarColumns(missing, arrays, "in.trx"); });
  EXPECT_EQ(e, "in.trx: no per-streamline array \"fa\" for the scalar range fa:0.3: (its per-streamline arrays: "
               "weight, rgb[3])");
  const std::vector<ScalarRange> beyond = {parseScalarRange("rgb[3]:0:1")};
  EXPECT_NE(test::errorOf([&] { resolveScalarColumns(beyond, arrays, "in.trx"); }).find("has 3 components, no [3]"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { resolveScalarColumns(missing, {}, "in.tck"); }).find("(its per-streamline arrays: none)"),
            std::string::npos);
}

// Keeps the "id" values of the streamlines it is given.
class KeptIds final : public TractogramWriter {
 public:
  void write(const Tractogram& chunk) override {
    for (const DataArray& a : chunk.per_streamline)  // (a TRX lists its dps in its own order)
      if (a.name == "id")
        for (float id : a.values) ids.push_back(size_t(id));
  }
  void finish() override {}
  std::vector<size_t> ids;
};

TEST(ScalarRange, runFilterKeepsTheFibersWhoseValuesLieInEveryRange) {
  test::TempDir dir;
  Tractogram t = test::smallTractogram(400, 3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 1);
  t.per_streamline = {{"id", 1, "float32", {}}, {"fa", 1, "float32", {}}, {"pair", 2, "float32", {}}};
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    t.per_streamline[0].values.push_back(float(s));
    t.per_streamline[1].values.push_back(s % 37 == 5 ? NAN : u(rng));
    t.per_streamline[2].values.push_back(u(rng) * 10 - 5);
    t.per_streamline[2].values.push_back(u(rng) * 10 - 5);
  }
  const std::string trx = dir.file("in.trx");
  writeTractogram(trx, t, TractogramHeader{});
  FilterCriteria c;
  c.scalar_ranges = {parseScalarRange("fa:0.25:0.8"), parseScalarRange("pair[1]:-1:")};
  auto reader = openTractogram(trx);
  KeptIds kept;
  const FilterReport report = runFilter(*reader, kept, FiberFilter(c), 2);
  std::vector<size_t> want;
  uint64_t by_fa = 0, by_pair = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s) {
    const double fa = t.per_streamline[1].values[s], pair = t.per_streamline[2].values[2 * s + 1];
    if (!(fa >= 0.25 && fa <= 0.8)) ++by_fa;  // NaN: dropped
    else if (!(pair >= -1)) ++by_pair;
    else want.push_back(s);
  }
  EXPECT_EQ(kept.ids, want);
  EXPECT_EQ(report.kept, want.size());
  ASSERT_EQ(report.by_scalar.size(), 2u);
  EXPECT_EQ(report.by_scalar[0], by_fa);
  EXPECT_EQ(report.by_scalar[1], by_pair);
  EXPECT_GT(by_fa, 0u);
  EXPECT_GT(by_pair, 0u);
  EXPECT_GT(want.size(), 20u);
}

TEST(ScalarRange, roiSetsReadAndWriteScalarRanges) {
  const RoiSet set = parseRoiSet(R"({"fibscope_roi_set": 1, "scalar_ranges": [
      {"name": "fa_mean", "min": 0.3},
      {"name": "rgb", "component": 2, "min": -1, "max": 2.5, "enabled": false}]})",
                                 "set.json");
  ASSERT_EQ(set.scalar_ranges.size(), 2u);
  EXPECT_EQ(scalarRangeSpec(set.scalar_ranges[0].range), "fa_mean:0.3:");
  EXPECT_TRUE(set.scalar_ranges[0].enabled);
  EXPECT_EQ(scalarRangeSpec(set.scalar_ranges[1].range), "rgb[2]:-1:2.5");
  EXPECT_FALSE(set.scalar_ranges[1].enabled);
  const FilterCriteria c = filterCriteria(set);
  ASSERT_EQ(c.scalar_ranges.size(), 1u);  // the enabled one
  const RoiSet again = parseRoiSet(roiSetJson(set, "set.json"), "set.json");
  ASSERT_EQ(again.scalar_ranges.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(scalarRangeSpec(again.scalar_ranges[i].range), scalarRangeSpec(set.scalar_ranges[i].range));
    EXPECT_EQ(again.scalar_ranges[i].enabled, set.scalar_ranges[i].enabled);
  }
  for (const char* bad : {R"({"fibscope_roi_set": 1, "scalar_ranges": [{"name": "a", "colour": 1}]})",
                          R"({"fibscope_roi_set": 1, "scalar_ranges": [{"min": 1}]})",
                          R"({"fibscope_roi_set": 1, "scalar_ranges": [{"name": "a", "min": 2, "max": 1}]})",
                          R"({"fibscope_roi_set": 1, "scalar_ranges": [{"name": "a", "component": -1}]})",
                          R"({"fibscope_roi_set": 1, "scalar_ranges": {"name": "a"}})"}) {
    SCOPED_TRACE(bad);
    const std::string e = test::errorOf([&] { parseRoiSet(bad, "set.json"); });
    EXPECT_EQ(e.rfind("set.json: scalar_ranges", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace fibscope
