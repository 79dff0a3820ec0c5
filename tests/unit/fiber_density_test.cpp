// FiberDensityAccumulator against a hand-counted case and a brute-force
// reference (every voxel of a segment's bounding box tested against the
// segment with the slab method), and `info` / `phantom OUT.fbl` on the CLI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <tuple>

#include "app/open_input.h"
#include "io/fiber_density.h"
#include "io/reader.h"
#include "test_support.h"

namespace fibscope {
namespace {

void addLine(Tractogram& t, std::array<float, 3> a, std::array<float, 3> b, float step) {
  const float dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
  const float length = std::sqrt(dx * dx + dy * dy + dz * dz);
  const int n = std::max(1, int(std::ceil(length / step)));
  std::vector<float> xyz;
  for (int i = 0; i <= n; ++i) {
    const float s = float(i) / float(n);
    xyz.insert(xyz.end(), {a[0] + s * dx, a[1] + s * dy, a[2] + s * dz});
  }
  t.addStreamline(xyz.data(), xyz.size() / 3);
}

TEST(FiberDensity, handCountedVoxels) {
  Tractogram t;
  addLine(t, {0.5f, 0.5f, 0.5f}, {9.5f, 0.5f, 0.5f}, 0.3f);  // voxels x 0..9
  addLine(t, {0.5f, 0.5f, 0.5f}, {4.5f, 0.5f, 0.5f}, 0.3f);  // x 0..4
  const float back[] = {0.2f, 0.5f, 0.5f, 1.5f, 0.5f, 0.5f, 0.3f, 0.5f, 0.5f};  // x 0, 1, back to 0: once each
  t.addStreamline(back, 3);
  // One long segment: y = 2.2 + 0.85 (x - 0.5) crosses x = 1 at y 2.625, y = 3
  // at x 1.44 and x = 2 at y 3.475: voxels (0,2) (1,2) (1,3) (2,3).
  const float diagonal[] = {0.5f, 2.2f, 0.5f, 2.5f, 3.9f, 0.5f};
  t.addStreamline(diagonal, 2);
  const float single[] = {20.5f, 0.5f, 0.5f};
  t.addStreamline(single, 1);
  t.addStreamline(nullptr, 0);  // empty: not a fiber

  FiberDensityAccumulator acc(1.0);
  acc.add(t);
  const FiberDensity d = acc.result();
  // Counts: x 0, 1 -> 3; x 2..4 -> 2; x 5..9 -> 1; the diagonal's 4 and the point's 1 -> 1.
  EXPECT_EQ(d.fibers, 5u);
  EXPECT_EQ(d.occupied_voxels, 15u);
  EXPECT_DOUBLE_EQ(d.occupied_cm3, 15 / 1000.0);
  EXPECT_NEAR(d.mean, 22.0 / 15.0, 1e-12);
  EXPECT_EQ(d.median, 1u);
  EXPECT_EQ(d.p90, 3u);
  EXPECT_EQ(d.p99, 3u);
  EXPECT_EQ(d.max, 3u);
  EXPECT_NEAR(d.single_fiber_fraction, 10.0 / 15.0, 1e-12);
  ASSERT_EQ(d.histogram.size(), 2u);
  EXPECT_EQ(d.histogram[0], 10u);
  EXPECT_EQ(d.histogram[1], 5u);

  // At 2 mm the first line covers x voxels 0..4, the second 0..2.
  FiberDensityAccumulator coarse(2.0);
  coarse.add(t);
  EXPECT_DOUBLE_EQ(coarse.result().occupied_cm3, double(coarse.result().occupied_voxels) * 8 / 1000.0);
  EXPECT_LT(coarse.result().occupied_voxels, d.occupied_voxels);
}

// Does segment a-b meet the voxel [lo, lo + 1)^3 (in voxel units)? Slab method.
bool segmentMeetsVoxel(const double* a, const double* b, const int64_t* lo) {
  double t0 = 0, t1 = 1;
  for (int c = 0; c < 3; ++c) {
    const double d = b[c] - a[c];
    const double v0 = double(lo[c]), v1 = double(lo[c] + 1);
    if (d == 0) {
      if (a[c] < v0 || a[c] >= v1) return false;
      continue;
    }
    double ta = (v0 - a[c]) / d, tb = (v1 - a[c]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

std::map<std::tuple<int64_t, int64_t, int64_t>, uint64_t> bruteForce(const Tractogram& t, double voxel) {
  std::map<std::tuple<int64_t, int64_t, int64_t>, uint64_t> counts;
  for (size_t f = 0; f < t.streamlineCount(); ++f) {
    std::set<std::tuple<int64_t, int64_t, int64_t>> mine;
    const size_t n = t.pointsIn(f);
    for (size_t i = 0; i < n; ++i) {
      const float* p = t.point(t.offsets[f] + i);
      const float* q = t.point(t.offsets[f] + std::min(i + 1, n - 1));
      const double a[3] = {p[0] / voxel, p[1] / voxel, p[2] / voxel};
      const double b[3] = {q[0] / voxel, q[1] / voxel, q[2] / voxel};
      int64_t lo[3], hi[3];
      for (int c = 0; c < 3; ++c) {
        lo[c] = int64_t(std::floor(std::min(a[c], b[c])));
        hi[c] = int64_t(std::floor(std::max(a[c], b[c])));
      }
      int64_t v[3];
      for (v[0] = lo[0]; v[0] <= hi[0]; ++v[0])
        for (v[1] = lo[1]; v[1] <= hi[1]; ++v[1])
          for (v[2] = lo[2]; v[2] <= hi[2]; ++v[2])
            if (segmentMeetsVoxel(a, b, v)) mine.insert({v[0], v[1], v[2]});
    }
    for (const auto& key : mine) ++counts[key];
  }
  return counts;
}

Tractogram randomWalks(size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Tractogram t;
  for (size_t s = 0; s < count; ++s) {
    const size_t n = 1 + rng() % 30;
    double p[3] = {-5 + 10 * u(rng), -5 + 10 * u(rng), -5 + 10 * u(rng)};
    std::vector<float> xyz;
    for (size_t i = 0; i < n; ++i) {
      xyz.insert(xyz.end(), {float(p[0]), float(p[1]), float(p[2])});
      const double step = 0.05 + 3 * u(rng);  // from well inside a voxel to across several
      double d[3] = {u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5};
      const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (int c = 0; c < 3; ++c) p[c] += step * d[c] / norm;
    }
    t.addStreamline(xyz.data(), n);
  }
  return t;
}

TEST(FiberDensity, equalsBruteForceVoxelSegmentTests) {
  for (const double voxel : {1.0, 0.7, 2.5}) {
    const Tractogram t = randomWalks(300, 7);
    FiberDensityAccumulator acc(voxel);
    acc.add(t);
    const FiberDensity d = acc.result();
    const auto reference = bruteForce(t, voxel);
    std::vector<uint64_t> counts;
    for (const auto& [key, c] : reference) counts.push_back(c);
    std::sort(counts.begin(), counts.end());
    ASSERT_EQ(d.occupied_voxels, reference.size()) << voxel;
    double sum = 0;
    for (uint64_t c : counts) sum += double(c);
    EXPECT_NEAR(d.mean, sum / double(counts.size()), 1e-9) << voxel;
    EXPECT_EQ(d.max, counts.back()) << voxel;
    EXPECT_EQ(d.median, counts[(counts.size() + 1) / 2 - 1]) << voxel;
    EXPECT_EQ(d.fibers, 300u);
  }
}

TEST(FiberDensity, chunksAndMergedAccumulatorsEqualOnePass) {
  const Tractogram all = randomWalks(200, 3);
  FiberDensityAccumulator whole(1.0);
  whole.add(all);
  Tractogram first, second;
  for (size_t f = 0; f < all.streamlineCount(); ++f)
    (f < 120 ? first : second).addStreamline(all.point(all.offsets[f]), all.pointsIn(f));
  FiberDensityAccumulator chunked(1.0);
  chunked.add(first);
  chunked.add(second);
  FiberDensityAccumulator a(1.0), b(1.0);
  a.add(first);
  b.add(second);
  a.merge(b);
  for (const FiberDensity& d : {chunked.result(), a.result()}) {
    const FiberDensity w = whole.result();
    EXPECT_EQ(d.fibers, w.fibers);
    EXPECT_EQ(d.occupied_voxels, w.occupied_voxels);
    EXPECT_DOUBLE_EQ(d.mean, w.mean);
    EXPECT_EQ(d.median, w.median);
    EXPECT_EQ(d.p99, w.p99);
    EXPECT_EQ(d.histogram, w.histogram);
  }
  FiberDensityAccumulator other(2.0);
  EXPECT_NE(test::errorOf([&] { a.merge(other); }), "");
}

TEST(FiberDensity, badVoxelSizesAndAbsurdCoordinatesAreHandled) {
  EXPECT_NE(test::errorOf([] { FiberDensityAccumulator(0.0); }), "");
  EXPECT_NE(test::errorOf([] { FiberDensityAccumulator(-1.0); }), "");
  EXPECT_NE(test::errorOf([] { FiberDensityAccumulator(NAN); }), "");
  // A 1e9 mm jump costs its two end voxels, not a billion visits; NaN breaks the line.
  Tractogram t;
  const float far[] = {0, 0, 0, 1e9f, 0, 0, NAN, 0, 0, 1e9f, 0.5f, 0};
  t.addStreamline(far, 4);
  FiberDensityAccumulator acc(1.0);
  acc.add(t);
  EXPECT_EQ(acc.result().fibers, 1u);
  EXPECT_LE(acc.result().occupied_voxels, 3u);
}

TEST(FiberDensityCommand, infoReportsTheDensityOfTheFile) {
  test::TempDir dir;
  const std::string tck = test::writePhantomTck(dir, "p.tck", 150, 4);
  const auto r = test::runFibscope("info --json --density-voxel 2 " + tck);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output.substr(r.output.find('[')));
  const auto& d = j[0]["fiber_density"];
  FiberDensityAccumulator acc(2.0);
  auto reader = openInput(tck);
  Tractogram chunk;
  while (reader->read(chunk)) acc.add(chunk);
  const FiberDensity expected = acc.result();
  EXPECT_EQ(d["voxel_mm"].get<double>(), 2.0);
  EXPECT_EQ(d["occupied_voxels"].get<uint64_t>(), expected.occupied_voxels);
  EXPECT_GT(expected.occupied_voxels, 100u);
  EXPECT_DOUBLE_EQ(d["fibers_per_voxel"]["mean"].get<double>(), expected.mean);
  EXPECT_EQ(d["fibers_per_voxel"]["median"].get<uint64_t>(), expected.median);
  EXPECT_EQ(d["histogram_log2"].get<std::vector<uint64_t>>(), expected.histogram);
  const auto text = test::runFibscope("info " + tck);
  EXPECT_NE(text.output.find("fiber density"), std::string::npos) << text.output;
  EXPECT_EQ(test::runFibscope("info --density-voxel 0 " + tck).output.find("fiber density"), std::string::npos);
  const auto bad = test::runFibscope("info --density-voxel 0.001 " + tck);
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
}

Tractogram readAll(const std::string& path) {
  auto reader = openInput(path);
  Tractogram all, chunk;
  while (reader->read(chunk)) all.append(chunk);
  return all;
}

TEST(FiberDensityCommand, phantomWritesFibletsStraightAsCompressingItsTck) {
  test::TempDir dir;
  const auto direct = test::runFibscope("phantom " + dir.file("p.fbl") + " -n 120 --seed 5");
  ASSERT_EQ(direct.exit_code, 0) << direct.output;
  EXPECT_NE(direct.output.find("points/s"), std::string::npos) << direct.output;
  ASSERT_EQ(test::runFibscope("phantom " + dir.file("p.tck") + " -n 120 --seed 5").exit_code, 0);
  ASSERT_EQ(test::runFibscope("compress " + dir.file("p.tck") + " " + dir.file("q.fbl")).exit_code, 0);
  const Tractogram a = readAll(dir.file("p.fbl")), b = readAll(dir.file("q.fbl"));
  EXPECT_EQ(a.streamlineCount(), 120u);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.positions, b.positions);  // the same fibers through the same codec
  // Never overwritten without --force; one line, exit code 2.
  const auto again = test::runFibscope("phantom " + dir.file("p.fbl") + " -n 10");
  EXPECT_EQ(again.exit_code, 2) << again.output;
  EXPECT_EQ(readAll(dir.file("p.fbl")).streamlineCount(), 120u);
}

}  // namespace
}  // namespace fibscope
