// `fibscope filter` on a .tck read in place (io/tck_scan.h,
// runTckFilterInPlace) and the filter's per-run boxes (select/block_boxes.h):
// the verdicts equal a test of every point against every region; ranges of
// every size, split anywhere (inside streamlines, at separators, inside a
// streamline longer than the read buffer, among empty streamlines), keep
// exactly what the reader's path keeps; damaged files go to the reader.
// (FilterAgainstTckedit in fiber_filter_test.cpp runs this path against
// MRtrix3's tckedit on tracker output.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "io/reader.h"
#include "io/tck_format.h"
#include "io/tck_scan.h"
#include "io/writer.h"
#include "select/block_boxes.h"
#include "select/fiber_filter.h"
#include "select/filter_run.h"
#include "select/region.h"
#include "test_support.h"

namespace fibscope {
namespace {

// tckedit's rules point by point, region by region: no boxes.
FilterVerdict everyPoint(const FilterCriteria& c, const float* xyz, size_t n) {
  if (n == 0) return {FilterReason::Length, 0};
  std::vector<const float*> points;
  for (size_t i = 0; i < n; ++i)
    if (!c.ends_only || i == 0 || i == n - 1) points.push_back(xyz + 3 * i);
  if (c.ends_only && n == 1) points.push_back(xyz);
  for (const float* p : points)
    for (size_t r = 0; r < c.exclude.size(); ++r)
      if (regionContains(c.exclude[r], p)) return {FilterReason::Exclude, uint32_t(r)};
  for (size_t r = 0; r < c.include.size(); ++r) {
    bool reached = false;
    for (const float* p : points) reached = reached || regionContains(c.include[r], p);
    if (!reached) return {FilterReason::Include, uint32_t(r)};
  }
  if (c.include_ordered.empty()) return {};
  size_t next = 0;
  for (const float* p : points)
    for (size_t r = 0; r < c.include_ordered.size(); ++r)
      if (regionContains(c.include_ordered[r], p)) {
        if (r == next) ++next;
        else if (r + 1 != next) return {FilterReason::IncludeOrdered, 0};
        break;
      }
  if (next != c.include_ordered.size()) return {FilterReason::IncludeOrdered, uint32_t(next)};
  return {};
}

// A random walk of n points in a 100 mm box, steps of about 1 mm.
std::vector<float> walk(std::mt19937& rng, size_t n) {
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<float> xyz;
  float p[3] = {40 * u(rng), 40 * u(rng), 40 * u(rng)}, d[3] = {u(rng), u(rng), u(rng)};
  for (size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      d[k] = 0.8f * d[k] + 0.4f * u(rng);
      p[k] += d[k];
      xyz.push_back(p[k]);
    }
  }
  return xyz;
}

TEST(BlockBoxes, holdEveryPointOfTheirRunAndTheWholeBox) {
  std::mt19937 rng(3);
  for (const size_t n : {size_t(0), size_t(1), size_t(31), size_t(32), size_t(33), size_t(95), size_t(200)}) {
    std::vector<float> xyz = walk(rng, n);
    if (n > 5) xyz[3 * 5 + 1] = NAN;  // a NaN widens nothing
    BlockBoxes b;
    computeBlockBoxes(xyz.data(), n, b);
    ASSERT_EQ(b.blocks(), (n + 31) / 32);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; ++i) {
      const float* box = b.box(i / 32);
      for (int k = 0; k < 3; ++k) {
        const float v = xyz[3 * i + k];
        if (std::isnan(v)) continue;
        EXPECT_LE(box[k], v);
        EXPECT_GE(box[3 + k], v);
        lo[k] = std::min(lo[k], v), hi[k] = std::max(hi[k], v);
      }
    }
    // Tight: each bound is one of the run's points.
    for (size_t r = 0; r < b.blocks(); ++r)
      for (int k = 0; k < 6; ++k) {
        bool attained = false;
        for (size_t i = 32 * r; i < std::min(n, 32 * r + 32); ++i) attained = attained || xyz[3 * i + k % 3] == b.box(r)[k];
        EXPECT_TRUE(attained) << "run " << r << " bound " << k;
      }
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(b.lo[k], lo[k]);
      EXPECT_EQ(b.hi[k], hi[k]);
    }
  }
}

TEST(FiberFilter, runBoxesDecideAsEveryPointTestedWould) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<std::vector<float>> lines;
  for (size_t s = 0; s < 600; ++s) lines.push_back(walk(rng, 1 + rng() % 300));
  auto randomRegion = [&](int kind) {
    char spec[160];
    if (kind == 0)
      std::snprintf(spec, sizeof spec, "sphere:%g,%g,%g,%g", 35 * u(rng), 35 * u(rng), 35 * u(rng), 6 + 8 * std::abs(u(rng)));
    else if (kind == 1) {
      const float x = 35 * u(rng), y = 35 * u(rng), z = 35 * u(rng);
      std::snprintf(spec, sizeof spec, "box:%g,%g,%g,%g,%g,%g", x, y, z, x + 15, y + 10, z + 12);
    } else {
      std::snprintf(spec, sizeof spec, "obox:%g,%g,%g,8,5,12,%g,%g,%g", 35 * u(rng), 35 * u(rng), 35 * u(rng),
                    90 * u(rng), 90 * u(rng), 90 * u(rng));
    }
    return parseRegion(spec);
  };
  size_t kept = 0, cases = 0;
  for (int trial = 0; trial < 24; ++trial) {
    FilterCriteria c;
    for (int i = 0; i < 1 + trial % 3; ++i) c.include.push_back(randomRegion((trial + i) % 3));
    for (int i = 0; i < trial % 4; ++i) c.exclude.push_back(randomRegion((trial + 2 * i) % 3));
    if (trial % 5 == 0) c.include_ordered = {randomRegion(0), randomRegion(1)};
    c.ends_only = trial % 6 == 5;
    const FiberFilter filter(c);
    for (const auto& xyz : lines) {
      const FilterVerdict got = filter.evaluate(xyz.data(), xyz.size() / 3);
      const FilterVerdict want = everyPoint(c, xyz.data(), xyz.size() / 3);
      ASSERT_EQ(int(got.reason), int(want.reason)) << "trial " << trial;
      if (want.reason != FilterReason::IncludeOrdered) {
        ASSERT_EQ(got.region, want.region) << "trial " << trial;
      }
      kept += got.kept();
      ++cases;
    }
  }
  // Not a trivial pass: some kept, most dropped.
  EXPECT_GT(kept, 20u);
  EXPECT_LT(kept, cases / 2);
}

// A tractogram with what splits must survive: empty streamlines (two
// separators in a row, runs of them, first and last), one-point ones, and
// one longer than the read buffer (1 MiB).
Tractogram awkwardTractogram(bool with_long, size_t count) {
  std::mt19937 rng(5);
  Tractogram t;
  t.addStreamline(nullptr, 0);
  for (size_t s = 0; s < count; ++s) {
    const size_t n = s % 37 == 0 ? 0 : s % 53 == 0 ? 1 : 2 + rng() % 120;
    const auto xyz = walk(rng, n);
    t.addStreamline(xyz.data(), n);
    if (s == count / 2 && with_long) {
      const auto big = walk(rng, 120000);  // 1.44 MB
      t.addStreamline(big.data(), 120000);
    }
  }
  t.addStreamline(nullptr, 0);
  return t;
}

FilterCriteria someCriteria() {
  FilterCriteria c;
  c.include = {parseRegion("sphere:0,0,0,30")};
  c.exclude = {parseRegion("box:20,-50,-50,50,50,50")};
  return c;
}

// Every range size on one file (tiny ones cut it everywhere, the largest
// split the streamline that outgrows the read buffer).
void expectRangesKeepWhatTheReaderKeeps(bool with_long, size_t count, const std::vector<uint64_t>& ranges) {
  test::TempDir dir;
  const std::string in = dir.file("in.tck");
  writeTractogram(in, awkwardTractogram(with_long, count), TractogramHeader{});
  const FiberFilter filter(someCriteria());
  auto reader = openTractogram(in);
  auto want_writer = createTractogramWriter(dir.file("want.tck"), reader->header(), {});
  const FilterReport want = runFilter(*reader, *want_writer, filter, 1);
  want_writer->finish();
  ASSERT_GT(want.kept, 10u);
  ASSERT_LT(want.kept, want.streamlines - 10);
  const Tractogram wanted = readTractogram(dir.file("want.tck"));
  for (const uint64_t range : ranges)
    for (const unsigned threads : {1u, 2u, 3u}) {
      SCOPED_TRACE("range " + std::to_string(range) + " bytes, " + std::to_string(threads) + " threads");
      const std::string out = dir.file("got.tck");
      std::vector<std::string> warnings;
      {
        WriterOptions wo;
        wo.overwrite = true;
        auto writer = createTractogramWriter(out, reader->header(), wo);
        const auto got = runTckFilterInPlace(in, *writer, filter, warnings, threads, {}, range);
        ASSERT_TRUE(got.has_value());
        writer->finish();
        EXPECT_EQ(got->streamlines, want.streamlines);
        EXPECT_EQ(got->points, want.points);
        EXPECT_EQ(got->kept, want.kept);
        EXPECT_EQ(got->kept_points, want.kept_points);
        EXPECT_EQ(got->by_include, want.by_include);
        EXPECT_EQ(got->by_exclude, want.by_exclude);
        EXPECT_EQ(got->by_length, want.by_length);
      }
      EXPECT_TRUE(warnings.empty());
      const Tractogram t = readTractogram(out);
      EXPECT_EQ(t.offsets, wanted.offsets);
      EXPECT_EQ(t.positions, wanted.positions);
    }
}

TEST(TckInPlace, rangesOfAnySizeKeepWhatTheReaderKeeps) {
  // ~45 KB: every triplet a range boundary at 12 bytes.
  expectRangesKeepWhatTheReaderKeeps(false, 60, {12, 36, 12 * 97, 0});
  // With a 1.44 MB streamline, longer than the 1 MiB read buffer.
  expectRangesKeepWhatTheReaderKeeps(true, 400, {12 * 4096, 12 * 50000, 12 * 200000, 0});
}

TEST(TckInPlace, damagedOrForeignFilesAreLeftToTheReader) {
  test::TempDir dir;
  const std::string good = dir.file("good.tck");
  Tractogram small = test::smallTractogram(50);
  writeTractogram(good, small, TractogramHeader{});
  const std::string bytes = test::readBytes(good);
  const TckHeaderInfo info = parseTckHeader(MappedFile(good), kTckMagic);
  const size_t data = info.data_offset;
  const float nan = NAN, inf = INFINITY;
  auto with = [&](size_t offset, const float* v, size_t count) {
    std::string b = bytes;
    std::memcpy(b.data() + offset, v, 4 * count);
    return b;
  };
  // The first streamline's separator.
  const size_t separator = data + 12 * small.pointsIn(0);
  const float infs[3] = {inf, inf, inf};
  struct Case {
    std::string name, bytes;
  };
  const std::vector<Case> cases = {
      {"mixed.tck", with(data + 12 * 3 + 4, &nan, 1)},              // one NaN among numbers
      {"early_inf.tck", with(separator, infs, 3)},                   // an Inf where a separator was
      {"truncated.tck", bytes.substr(0, bytes.size() - 12)},         // no terminator
      {"ragged.tck", bytes.substr(0, bytes.size() - 4)},             // not whole triplets
  };
  const FiberFilter filter(someCriteria());
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.file(c.name);
    test::writeBytes(path, c.bytes);
    auto writer = createTractogramWriter(dir.file("out.tck"), TractogramHeader{}, {});
    std::vector<std::string> warnings;
    for (const uint64_t range : {uint64_t(12 * 7), uint64_t(0)})
      EXPECT_FALSE(runTckFilterInPlace(path, *writer, filter, warnings, 2, {}, range).has_value());
  }
  // `fibscope filter` then says what the reader says, and keeps what it reads.
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.file(c.name), out = dir.file("cli.tck");
    const auto r = test::runFibscope("filter --force " + path + " " + out + " --min-length 0");
    if (c.name == "mixed.tck") {
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_NE(r.output.find("NaN or Inf in only some coordinates"), std::string::npos) << r.output;
      EXPECT_FALSE(std::filesystem::exists(out));
      continue;
    }
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("warning: " + path), std::string::npos) << r.output;
    const Tractogram read = readTractogram(path), kept = readTractogram(out);
    EXPECT_EQ(kept.offsets, read.offsets);
    EXPECT_EQ(kept.positions, read.positions);
  }
}

TEST(TckInPlace, aCountThatDisagreesIsSaidAsTheReaderSaysIt) {
  test::TempDir dir;
  const std::string path = dir.file("count.tck");
  writeTractogram(path, test::smallTractogram(30), TractogramHeader{});
  std::string b = test::readBytes(path);
  const size_t at = b.find("count: ");
  ASSERT_NE(at, std::string::npos);
  b[at + 7 + TckHeaderText::kCountDigits - 1] = '7';  // 30 -> 37
  test::writeBytes(path, b);
  const FiberFilter filter(someCriteria());
  auto writer = createTractogramWriter(dir.file("out.tck"), TractogramHeader{}, {});
  std::vector<std::string> warnings;
  ASSERT_TRUE(runTckFilterInPlace(path, *writer, filter, warnings, 2).has_value());
  auto reader = openTractogram(path);
  Tractogram chunk;
  while (reader->read(chunk, 1000)) {
  }
  EXPECT_EQ(warnings, reader->warnings());
  ASSERT_EQ(warnings.size(), 1u);
}

}  // namespace
}  // namespace fibscope
