// --tube-radius-from and its ranges (app/tube_options.h): the radius of
// every node is the file's value at that point (or fiber) mapped linearly
// from the data range onto the radius range, read back through the real
// readers (TRX dpv and dps, a .tck with a .tsf beside it), for a
// selection that skips fibers and reorders them; bad names and ranges are
// one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "app/tube_options.h"
#include "core/error.h"
#include "io/tsf.h"
#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

// Three straight fibers along x (4, 3 and 5 points, 2 mm apart, no two
// collinear in a way resampling could merge: tolerance 0 keeps every
// point), with a per-point "fa" in [0, 1] and a per-streamline "w".
Tractogram threeFibers() {
  Tractogram t;
  const size_t counts[] = {4, 3, 5};
  for (size_t f = 0; f < 3; ++f) {
    std::vector<float> xyz;
    for (size_t i = 0; i < counts[f]; ++i) {
      xyz.insert(xyz.end(), {2.0f * float(i), 10.0f * float(f), 0.0f});
    }
    t.addStreamline(xyz.data(), counts[f]);
  }
  DataArray fa{"fa", 1, "float32", {}};
  for (size_t p = 0; p < t.pointCount(); ++p) fa.values.push_back(float(p) / float(t.pointCount() - 1));
  DataArray w{"w", 1, "float32", {2.0f, 4.0f, 6.0f}};
  t.per_point.push_back(fa);
  t.per_streamline.push_back(w);
  return t;
}

float expected(float v, float d0, float d1, float r0, float r1) {
  return r0 + std::clamp((v - d0) / (d1 - d0), 0.0f, 1.0f) * (r1 - r0);
}

// Node radii of `model`'s tube of input fiber `fiber`.
std::vector<float> radii(const TubeModel& model, uint32_t fiber) {
  for (const TubeModel::Tube& t : model.tubes)
    if (t.fiber == fiber) {
      std::vector<float> r;
      for (uint32_t n = 0; n < t.node_count; ++n) r.push_back(model.nodes[t.first_node + n].position_radius.w);
      return r;
    }
  ADD_FAILURE() << "no tube for fiber " << fiber;
  return {};
}

TubeCliOptions options(const std::string& from, const std::string& data, const std::string& range) {
  TubeCliOptions o;
  o.fibers = "2,0";  // skips fiber 1, reversed order
  o.resample_tolerance_mm = 0.0f;
  o.radius_from = from;
  o.radius_data = data;
  o.radius_range = range;
  return o;
}

TEST(TubeRadiusOptions, perPointAndPerFiberRadiiAreTheFilesValuesMapped) {
  test::TempDir dir;
  const Tractogram t = threeFibers();
  const std::string trx = dir.file("t.trx");
  writeTractogram(trx, t, TractogramHeader{});

  // Per point, the data range given: fiber 2's points are 7..11 of 12.
  const TubeModel pp = loadTubeModel(trx, 0, options("fa", "0,0.5", "0.25,1.25"));
  ASSERT_EQ(pp.tubes.size(), 2u);
  const std::vector<float> r2 = radii(pp, 2), r0 = radii(pp, 0);
  ASSERT_EQ(r2.size(), 5u);
  ASSERT_EQ(r0.size(), 4u);
  for (size_t i = 0; i < 5; ++i) EXPECT_NEAR(r2[i], expected(t.per_point[0].values[7 + i], 0, 0.5f, 0.25f, 1.25f), 1e-5);
  for (size_t i = 0; i < 4; ++i) EXPECT_NEAR(r0[i], expected(t.per_point[0].values[i], 0, 0.5f, 0.25f, 1.25f), 1e-5);

  // Per fiber, the data range from the selected fibers (w 2 and 6).
  const TubeModel pf = loadTubeModel(trx, 0, options("w", "", "0.5,1.5"));
  for (float r : radii(pf, 0)) EXPECT_NEAR(r, 0.5f, 1e-6);
  for (float r : radii(pf, 2)) EXPECT_NEAR(r, 1.5f, 1e-6);
}

TEST(TubeRadiusOptions, aTsfBesideATckGivesThePerPointRadius) {
  test::TempDir dir;
  const Tractogram t = threeFibers();
  const std::string tck = dir.file("t.tck"), tsf = dir.file("fa.tsf");
  writeTractogram(tck, t, TractogramHeader{});
  writeTsf(tsf, t, "fa", TractogramHeader{});
  const TubeModel m = loadTubeModel(tck, 0, options(tsf, "", "0.2,1"));
  // Default data range: the selected points' fa, 0 .. 1 (points 0 and 11).
  const std::vector<float> r2 = radii(m, 2);
  ASSERT_EQ(r2.size(), 5u);
  EXPECT_NEAR(r2.back(), 1.0f, 1e-5);
  EXPECT_NEAR(radii(m, 0).front(), 0.2f, 1e-5);
  for (size_t i = 0; i < 5; ++i) EXPECT_NEAR(r2[i], 0.2f + 0.8f * t.per_point[0].values[7 + i], 1e-5);
}

TEST(TubeRadiusOptions, badNamesAndRangesAreOneLineErrors) {
  test::TempDir dir;
  Tractogram t = threeFibers();
  t.per_point.push_back(DataArray{"rgb", 3, "float32", std::vector<float>(3 * t.pointCount(), 0.5f)});
  const std::string trx = dir.file("t.trx"), tck = dir.file("t.tck");
  writeTractogram(trx, t, TractogramHeader{});
  writeTractogram(tck, threeFibers(), TractogramHeader{});
  const auto fails = [](const std::string& path, const TubeCliOptions& o, const std::string& want) {
    try {
      loadTubeModel(path, 0, o);
      ADD_FAILURE() << "no error, wanted " << want;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(want), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  fails(trx, options("md", "", "0.2,1"), "no array of that name (it has:");
  fails(trx, options("rgb", "", "0.2,1"), "3 components");
  fails(trx, options("fa", "1,0", "0.2,1"), "--tube-radius-data");
  fails(trx, options("fa", "", "1"), "--tube-radius-range");
  fails(trx, options("fa", "", "0,1"), "> 0 mm");
  fails(trx, options("fa.tsf", "", "0.2,1"), "needs a .tck input");
  fails(tck, options(dir.file("missing.tsf"), "", "0.2,1"), "missing.tsf");
}

}  // namespace
}  // namespace fibscope
