// The CPU reference of fiber bundling (bundling/bundle_reference.h): each
// stage's formula on hand-made inputs, the separable density against the
// direct 3-D convolution, and whole runs on a small model.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "bundling/bundle_params.h"
#include "bundling/bundle_reference.h"
#include "bundling/bundle_setup.h"
#include "bundling_test_model.h"
#include "test_support.h"

namespace fibscope {
namespace {

// Half-millimetre voxels, 1 mm samples and quarter steps: the two-fiber
// and sheet models' runs, where a whole step would jump their gaps.
BundleParams fineParams(double radius, uint32_t iterations) {
  BundleParams p;
  p.voxel_mm = 0.5;
  p.step_mm = 1;
  p.radius = radius;
  p.iterations = iterations;
  p.advection = 0.25;
  return p;
}

BundleGrid smallGrid(glm::uvec3 size, double voxel = 2.0) {
  BundleGrid g;
  g.origin = glm::dvec3(-10.0, -7.0, -5.0);
  g.voxel = voxel;
  g.size = size;
  return g;
}

std::vector<double> randomCounts(const BundleGrid& g, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> c(0, 9);
  std::vector<double> counts(g.voxelCount());
  for (double& v : counts) v = c(rng) < 7 ? 0 : c(rng);
  return counts;
}

// One fiber of `n` samples along direction `d` from `start`, `spacing` apart.
BundleSamples line(glm::dvec3 start, glm::dvec3 d, int n, double spacing) {
  BundleSamples s;
  for (int i = 0; i < n; ++i) s.push_back(start + d * (spacing * i));
  return s;
}

double maxAbs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

}  // namespace

TEST(Bundling, paramsDefaultToThePapersValues) {
  const BundleParams p;
  EXPECT_EQ(p.iterations, 15u);
  EXPECT_EQ(p.radius_decay, 0.95);
  EXPECT_EQ(p.smoothing, 0.9);
  EXPECT_EQ(p.smoothing_length, 1.0);
  EXPECT_EQ(p.relaxation, 0.85);
  EXPECT_EQ(p.voxel_fraction, 0.003);
  EXPECT_EQ(p.step_fraction, 0.01);
  EXPECT_EQ(bundleParamsProblem(p), "");
}

TEST(Bundling, invalidParamsNameTheParameter) {
  BundleParams p;
  p.radius = 0.5;
  EXPECT_NE(bundleParamsProblem(p).find("radius is 0.5"), std::string::npos) << bundleParamsProblem(p);
  p = {};
  p.smoothing = 1.5;
  EXPECT_NE(bundleParamsProblem(p).find("smoothing"), std::string::npos);
  p = {};
  p.relaxation = -0.1;
  EXPECT_NE(bundleParamsProblem(p).find("relaxation"), std::string::npos);
  p = {};
  p.iterations = 0;
  EXPECT_NE(test::errorOf([&] { validateBundleParams(p); }).find("iterations"), std::string::npos);
  p = {};
  p.radius_decay = 1.2;
  EXPECT_NE(bundleParamsProblem(p).find("radius decay"), std::string::npos);
  p = {};
  p.structure_power = 9;
  EXPECT_NE(bundleParamsProblem(p).find("structure power is 9"), std::string::npos) << bundleParamsProblem(p);
  p = {};
  p.structure_scale = 0.05;
  EXPECT_NE(bundleParamsProblem(p).find("structure scale"), std::string::npos);
  EXPECT_NE(test::errorOf([] { parseBundleMode("radial"); }).find("radial"), std::string::npos);
}

TEST(Bundling, planCoversTheBoxWidenedByTheRadius) {
  const Tractogram t = test::wavyBundlingModel(30);
  BundleParams p;
  p.radius = 3;
  const BundleSetup s = planBundling(t, p);
  glm::dvec3 lo(1e9), hi(-1e9);
  for (size_t i = 0; i < t.pointCount(); ++i) {
    lo = glm::min(lo, glm::dvec3(t.point(i)[0], t.point(i)[1], t.point(i)[2]));
    hi = glm::max(hi, glm::dvec3(t.point(i)[0], t.point(i)[1], t.point(i)[2]));
  }
  const double largest = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  EXPECT_DOUBLE_EQ(s.grid.voxel, 0.003 * largest);
  EXPECT_DOUBLE_EQ(s.step_mm, 0.01 * (hi.z - lo.z));
  for (int a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(s.grid.origin[a], lo[a] - 3 * s.grid.voxel);
    EXPECT_GE(s.grid.origin[a] + s.grid.voxel * s.grid.size[a], hi[a] + 3 * s.grid.voxel - 1e-9);
  }
  EXPECT_EQ(s.sample_offsets.size(), t.streamlineCount() + 1);
  EXPECT_EQ(bundleSampleCount(0, 1), 1u);
  EXPECT_EQ(bundleSampleCount(0.5, 1), 2u);
  EXPECT_EQ(bundleSampleCount(10, 1), 11u);
  EXPECT_EQ(bundleSampleCount(10.2, 1), 12u);
}

TEST(Bundling, planRejectsModelsWithoutExtentOrWithNaN) {
  Tractogram t;
  EXPECT_NE(test::errorOf([&] { planBundling(t, {}); }).find("no point"), std::string::npos);
  const float same[6] = {1, 2, 3, 1, 2, 3};
  t.addStreamline(same, 2);
  EXPECT_NE(test::errorOf([&] { planBundling(t, {}); }).find("no extent"), std::string::npos);
  const float nan[6] = {1, 2, 3, NAN, 2, 3};
  t.addStreamline(nan, 2);
  EXPECT_NE(test::errorOf([&] { planBundling(t, {}); }).find("not finite"), std::string::npos);
}

TEST(Bundling, resamplingPlacesEqualIntervalsAndKeepsTheEnds) {
  Tractogram t;
  const float pts[] = {0, 0, 0, 3, 0, 0, 3, 4, 0, 3, 4, 0.5f};  // length 7.5, uneven segments
  t.addStreamline(pts, 4);
  BundleSetup s;
  s.step_mm = 1;
  s.sample_offsets = {0, bundleSampleCount(7.5, 1)};
  ASSERT_EQ(s.sampleCount(), 9u);
  const BundleSamples r = resampleReference(t, s);
  const double spacing = 7.5 / 8;
  for (size_t i = 1; i < r.size(); ++i) {
    // Along the polyline: on the same segment the chord is the arc.
    const bool same_segment =
        (i * spacing <= 3 || (i - 1) * spacing >= 3) && (i * spacing <= 7 || (i - 1) * spacing >= 7);
    if (same_segment) {
      EXPECT_NEAR(glm::length(r[i] - r[i - 1]), spacing, 1e-12) << i;
    }
  }
  EXPECT_EQ(r.front(), glm::dvec3(0, 0, 0));
  EXPECT_NEAR(glm::length(r.back() - glm::dvec3(3, 4, 0.5)), 0, 1e-6);
  EXPECT_NEAR(glm::length(r[4] - glm::dvec3(3, 3.75 - 3 + 0.0, 0)), 0, 1e-6);  // arc 3.75: 0.75 up the second segment
}

TEST(Bundling, separableDensityEqualsTheDirectProductKernelConvolution) {
  for (const double radius : {1.0, 2.5, 3.0, 4.2}) {
    const BundleGrid g = smallGrid({13, 11, 9});
    const std::vector<double> counts = randomCounts(g, 7);
    const std::vector<double> separable = densitySeparableReference(counts, g, radius);
    const std::vector<double> direct = densityDirectReference(counts, g, radius);
    const double scale = maxAbs(direct);
    ASSERT_GT(scale, 1);
    for (size_t i = 0; i < counts.size(); ++i)
      ASSERT_NEAR(separable[i], direct[i], 1e-12 * scale) << radius << " " << i;
  }
}

TEST(Bundling, densityKernelIsTheProductOfParabolasNotTheRadialOne) {
  const BundleGrid g = smallGrid({9, 9, 9});
  std::vector<double> counts(g.voxelCount(), 0.0);
  counts[g.index(4, 4, 4)] = 1;
  const double R = 3;
  const std::vector<double> d = densitySeparableReference(counts, g, R);
  auto k = [&](double x) { return 1 - x * x / (R * R); };
  EXPECT_DOUBLE_EQ(d[g.index(4, 4, 4)], 1.0);
  EXPECT_DOUBLE_EQ(d[g.index(5, 4, 4)], k(1));
  EXPECT_DOUBLE_EQ(d[g.index(5, 6, 3)], k(1) * k(2) * k(1));
  // The radial parabola 1 - |d|^2 / R^2 would give 1 - 6/9 here.
  EXPECT_GT(std::abs(d[g.index(5, 6, 3)] - (1 - 6.0 / 9)), 0.1);
  EXPECT_EQ(d[g.index(7, 4, 4)], 0.0);  // |d| = R: weight 0
  EXPECT_EQ(d[g.index(0, 4, 4)], 0.0);
}

TEST(Bundling, gradientIsExactOnALinearDensity) {
  const BundleGrid g = smallGrid({6, 5, 4}, 0.5);
  std::vector<double> density(g.voxelCount());
  for (uint32_t z = 0; z < 4; ++z)
    for (uint32_t y = 0; y < 5; ++y)
      for (uint32_t x = 0; x < 6; ++x) density[g.index(x, y, z)] = 2.0 * x + 3.0 * y - 1.0 * z + 0.25 * x * y;
  const std::vector<glm::dvec3> grad = gradientReference(density, g);
  // Interior: central differences of the bilinear term are exact too.
  EXPECT_NEAR(grad[g.index(2, 2, 1)].x, (2 + 0.25 * 2) / 0.5, 1e-12);
  EXPECT_NEAR(grad[g.index(2, 2, 1)].y, (3 + 0.25 * 2) / 0.5, 1e-12);
  EXPECT_NEAR(grad[g.index(2, 2, 1)].z, -1 / 0.5, 1e-12);
  // Faces: one-sided.
  EXPECT_NEAR(grad[g.index(0, 0, 0)].x, 2 / 0.5, 1e-12);
  EXPECT_NEAR(grad[g.index(5, 4, 3)].x, (2 + 0.25 * 4) / 0.5, 1e-12);
  EXPECT_NEAR(grad[g.index(5, 4, 3)].z, -1 / 0.5, 1e-12);
  // Trilinear at a voxel centre is the voxel's value; halfway, the mean.
  const glm::dvec3 c = g.origin + g.voxel * glm::dvec3(2.5, 2.5, 1.5);
  EXPECT_NEAR(glm::length(interpolateGradient(grad, g, c) - grad[g.index(2, 2, 1)]), 0, 1e-12);
  const glm::dvec3 h = g.origin + g.voxel * glm::dvec3(3.0, 2.5, 1.5);
  EXPECT_NEAR(glm::length(interpolateGradient(grad, g, h) - (grad[g.index(2, 2, 1)] + grad[g.index(3, 2, 1)]) * 0.5), 0,
              1e-12);
}

TEST(Bundling, advectionMovesOrthogonallyToTheFiberByTheStep) {
  const BundleGrid g = smallGrid({12, 10, 8});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<glm::dvec3> grad(g.voxelCount());
  for (glm::dvec3& v : grad) v = {u(rng), u(rng), u(rng)};
  const glm::dvec3 d = glm::normalize(glm::dvec3(1, 0.3, -0.2));
  const BundleSamples s = line(glm::dvec3(-7, -4, -2), d, 8, 1.5);
  const std::vector<uint32_t> offsets = {0, 8};
  const double step = 1.7;
  const BundleSamples a = advectReference(s, offsets, grad, g, step, false);
  for (size_t i = 0; i < s.size(); ++i) {
    const glm::dvec3 m = a[i] - s[i];
    EXPECT_NEAR(glm::dot(m, d), 0, 1e-12) << i;
    const glm::dvec3 gi = interpolateGradient(grad, g, s[i]);
    const glm::dvec3 expect = (gi - d * glm::dot(d, gi)) * (step / glm::length(gi));
    EXPECT_NEAR(glm::length(m - expect), 0, 1e-12) << i;
    EXPECT_LE(glm::length(m), step + 1e-12);
    EXPECT_GT(glm::length(m), 0.0);
    // u = d x (g x d) is the same vector.
    EXPECT_NEAR(glm::length(glm::cross(d, glm::cross(gi, d)) * (step / glm::length(gi)) - m), 0, 1e-12);
  }
  const BundleSamples anchored = advectReference(s, offsets, grad, g, step, true);
  EXPECT_EQ(anchored.front(), s.front());
  EXPECT_EQ(anchored.back(), s.back());
  EXPECT_NE(anchored[3], s[3]);
}

TEST(Bundling, smoothingBlendsWithASymmetricWindowMean) {
  const BundleSamples s = {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}, {3, 4, 0}, {4, 0, 1}};
  const std::vector<uint32_t> offsets = {0, 5};
  const BundleSamples out = smoothReference(s, offsets, 0.9, 1, false);
  const glm::dvec3 mean2 = (s[1] + s[2] + s[3]) / 3.0;
  EXPECT_NEAR(glm::length(out[2] - (0.1 * s[2] + 0.9 * mean2)), 0, 1e-12);
  EXPECT_EQ(out[0], s[0]);  // an end: no window that stays symmetric
  EXPECT_EQ(out[4], s[4]);
  const BundleSamples wide = smoothReference(s, offsets, 0.5, 2, false);
  const glm::dvec3 mean1 = (s[0] + s[1] + s[2]) / 3.0;  // window 2 shrunk to 1 next to the end
  EXPECT_NEAR(glm::length(wide[1] - (0.5 * s[1] + 0.5 * mean1)), 0, 1e-12);
  const glm::dvec3 mean_all = (s[0] + s[1] + s[2] + s[3] + s[4]) / 5.0;
  EXPECT_NEAR(glm::length(wide[2] - (0.5 * s[2] + 0.5 * mean_all)), 0, 1e-12);
  // A straight, evenly sampled fiber does not shrink.
  const BundleSamples straight = line(glm::dvec3(1, 2, 3), glm::dvec3(0, 0.6, 0.8), 9, 1.5);
  const BundleSamples kept = smoothReference(straight, {0, 9}, 0.9, 3, false);
  for (size_t i = 0; i < straight.size(); ++i) EXPECT_NEAR(glm::length(kept[i] - straight[i]), 0, 1e-12) << i;
}

TEST(Bundling, relaxationInterpolatesTowardsTheOriginals) {
  const BundleSamples o = {{0, 0, 0}, {1, 1, 1}};
  const BundleSamples b = {{2, 0, 0}, {1, 3, -1}};
  const BundleSamples r = relaxReference(o, b, 0.85);
  EXPECT_NEAR(glm::length(r[0] - glm::dvec3(1.7, 0, 0)), 0, 1e-12);
  EXPECT_NEAR(glm::length(r[1] - glm::dvec3(1, 2.7, -0.7)), 0, 1e-12);
  EXPECT_EQ(relaxReference(o, b, 1.0)[1], b[1]);
  EXPECT_EQ(relaxReference(o, b, 0.0)[1], o[1]);
}

TEST(Bundling, mapBackKeepsThePointsAndInterpolatesTheDisplacement) {
  Tractogram t;
  const float pts[] = {0, 0, 0, 1, 0, 0, 2.5f, 0, 0, 4, 0, 0};  // length 4
  t.addStreamline(pts, 4);
  BundleSetup s;
  s.step_mm = 2;
  s.sample_offsets = {0, 3};  // samples at 0, 2, 4
  const BundleSamples o = resampleReference(t, s);
  BundleSamples b = o;
  b[0] += glm::dvec3(0, 1, 0);
  b[1] += glm::dvec3(0, 3, 0);
  b[2] += glm::dvec3(0, 0, 2);
  const std::vector<float> m = mapBackReference(t, s, o, b);
  ASSERT_EQ(m.size(), t.positions.size());
  auto at = [&](int i) { return glm::dvec3(m[3 * i], m[3 * i + 1], m[3 * i + 2]); };
  EXPECT_NEAR(glm::length(at(0) - glm::dvec3(0, 1, 0)), 0, 1e-6);
  EXPECT_NEAR(glm::length(at(1) - glm::dvec3(1, 2, 0)), 0, 1e-6);         // halfway between samples 0 and 1
  EXPECT_NEAR(glm::length(at(2) - glm::dvec3(2.5, 2.25, 0.5)), 0, 1e-6);  // a quarter from sample 1 to 2
  EXPECT_NEAR(glm::length(at(3) - glm::dvec3(4, 0, 2)), 0, 1e-6);
  // No displacement: the points come back as they were.
  EXPECT_EQ(mapBackReference(t, s, o, o), t.positions);
}

TEST(Bundling, referenceRunPullsNeighbouringFibersTogether) {
  // Two parallel straight fibers 3 mm apart inside one kernel radius.
  Tractogram t;
  std::vector<float> a, b;
  for (int i = 0; i <= 20; ++i) {
    a.insert(a.end(), {float(i), 0, 0});
    b.insert(b.end(), {float(i), 3, 0.5f});
  }
  t.addStreamline(a.data(), 21);
  t.addStreamline(b.data(), 21);
  BundleParams p;
  p.voxel_mm = 0.5;
  p.step_mm = 1;
  p.radius = 8;
  p.iterations = 3;
  p.advection = 0.25;  // 1 mm: a full R (4 mm) would jump past the other fiber
  const std::vector<float> out = bundleReference(t, p);
  ASSERT_EQ(out.size(), t.positions.size());
  auto gap = [&](const std::vector<float>& pos, int i) {
    const int j = 21 + i;
    return std::hypot(pos[3 * i + 1] - pos[3 * j + 1], pos[3 * i + 2] - pos[3 * j + 2]);
  };
  EXPECT_LT(gap(out, 10), 0.5 * gap(t.positions, 10));
  // The motion is across the fibers: x of the middle points barely moves.
  EXPECT_NEAR(out[3 * 10], 10.0f, 0.05f);
  EXPECT_EQ(bundleReference(t, p), out);  // deterministic
}

TEST(Bundling, anisotropicSplatIsAnEllipsoidAlongTheFiber) {
  const BundleGrid g = smallGrid({21, 21, 21}, 1.0);
  // One fiber along x through the centre of voxel (10, 10, 10).
  const glm::dvec3 c = g.origin + glm::dvec3(10.5);
  const BundleSamples s = {c - glm::dvec3(1, 0, 0), c, c + glm::dvec3(1, 0, 0)};
  const std::vector<uint32_t> offsets = {0, 3};
  const double ra = 6, rb = 3;
  // A fiber of one sample has no direction: isotropic with Rb.
  const std::vector<double> d = splatReference({s[1]}, {0, 1}, g, ra, rb, false);
  EXPECT_DOUBLE_EQ(d[g.index(10, 10, 10)], 1.0);
  EXPECT_DOUBLE_EQ(d[g.index(11, 10, 10)], 1 - 1 / (rb * rb));
  const std::vector<double> e = splatReference(s, offsets, g, ra, rb, false);
  // The middle sample alone at offsets along and across the fiber (the
  // other two add theirs: compare the difference of two splats).
  const std::vector<double> ends = splatReference({s[0], s[2]}, {0, 2}, g, ra, rb, false);
  auto mid = [&](uint32_t x, uint32_t y, uint32_t z) { return e[g.index(x, y, z)] - ends[g.index(x, y, z)]; };
  EXPECT_NEAR(mid(14, 10, 10), 1 - 16 / (ra * ra), 1e-12);  // 4 along
  EXPECT_NEAR(mid(10, 12, 10), 1 - 4 / (rb * rb), 1e-12);   // 2 across
  EXPECT_NEAR(mid(10, 10, 13), 0.0, 1e-12);                 // 3 across: the rim
  EXPECT_NEAR(mid(13, 11, 10), 1 - 9 / (ra * ra) - 1 / (rb * rb), 1e-12);
  // Fixed point: each term rounded to 1/256.
  const std::vector<double> q = splatReference(s, offsets, g, ra, rb, true);
  for (size_t i = 0; i < q.size(); ++i) {
    ASSERT_NEAR(q[i], e[i], 3 * 0.5 / 256 + 1e-12);
    ASSERT_EQ(q[i] * 256, std::round(q[i] * 256));
  }
}

TEST(Bundling, anisotropicModeKeepsFibersFartherApartThanTheIsotropic) {
  // Two parallel fibers 3 mm apart: the isotropic kernel (4 mm) pulls them
  // together, the anisotropic one (2 mm across) barely.
  Tractogram t;
  std::vector<float> a, b;
  for (int i = 0; i <= 20; ++i) {
    a.insert(a.end(), {float(i), 0, 0});
    b.insert(b.end(), {float(i), 3, 0});
  }
  t.addStreamline(a.data(), 21);
  t.addStreamline(b.data(), 21);
  BundleParams p = fineParams(8, 2);
  const std::vector<float> iso = bundleReference(t, p);
  p.mode = BundleMode::Anisotropic;
  const std::vector<float> aniso = bundleReference(t, p);
  const float iso_gap = iso[3 * 31 + 1] - iso[3 * 10 + 1], aniso_gap = aniso[3 * 31 + 1] - aniso[3 * 10 + 1];
  EXPECT_LT(iso_gap, 2.0f);
  EXPECT_GT(aniso_gap, 2.5f);
}

}  // namespace fibscope

namespace fibscope {
namespace {

// A symmetric matrix with eigenvalues `values` along the columns of the
// rotation about axis (1, 2, 3) by `angle`.
glm::dmat3 withEigen(glm::dvec3 values, double angle) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1, 2, 3));
  const double c = std::cos(angle), s = std::sin(angle);
  const glm::dmat3 k(0, axis.z, -axis.y, -axis.z, 0, axis.x, axis.y, -axis.x, 0);
  const glm::dmat3 r = glm::dmat3(1.0) + s * k + (1 - c) * k * k;  // Rodrigues
  glm::dmat3 d(0.0);
  for (int i = 0; i < 3; ++i) d[i][i] = values[i];
  return r * d * glm::transpose(r);
}

double maxEntry(const glm::dmat3& m) {
  double e = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) e = std::max(e, std::abs(m[i][j]));
  return e;
}

// A sheet of `n` parallel fibers along x, 1 mm apart in y, in the plane z =
// 0 up to a jitter: what isotropic bundling breaks into strands.
Tractogram sheetModel(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  Tractogram t;
  for (int f = 0; f < n; ++f) {
    const float y = float(f) + 0.3f * u(rng), z = 0.4f * u(rng);
    std::vector<float> xyz;
    for (int i = 0; i <= 40; ++i) xyz.insert(xyz.end(), {float(i), y, z});
    t.addStreamline(xyz.data(), 41);
  }
  return t;
}

}  // namespace

TEST(Bundling, symmetricEigenRecoversAKnownDecomposition) {
  for (const glm::dvec3& values : {glm::dvec3(5, 2, 0.5), glm::dvec3(1, 1, 1e-3), glm::dvec3(4, 0, 0)}) {
    const glm::dmat3 m = withEigen(values, 0.7);
    glm::dvec3 lambda;
    glm::dmat3 e;
    symmetricEigenReference(m, &lambda, &e);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(lambda[k], values[k], 1e-12);
      EXPECT_NEAR(glm::length(e[k]), 1, 1e-12);
      EXPECT_NEAR(glm::length(m * e[k] - lambda[k] * e[k]), 0, 1e-12);
    }
  }
}

TEST(Bundling, structureFilterIsTheNormalisedTensorToThePower) {
  // sum (lambda_k / lambda_1)^p e_k e_k^T equals (J / lambda_1)^p, which the
  // GPU takes by matrix products.
  const glm::dmat3 j = withEigen(glm::dvec3(8, 3, 1), 1.3);
  glm::dmat3 a = j / 8.0, power = glm::dmat3(1.0);
  for (uint32_t p = 1; p <= 4; ++p) {
    power = power * a;
    EXPECT_LT(maxEntry(structureFilterReference(j, p) - power), 1e-12) << p;
  }
  // No gradient: the identity (the plain advection).
  EXPECT_EQ(structureFilterReference(glm::dmat3(0.0), 2), glm::dmat3(1.0));
}

TEST(Bundling, structureTensorOfALinearDensityIsItsGradientSquared) {
  // Cell means of a linear density are linear, their differences exact
  // (one-sided ones too), so every cell holds a a^T.
  EXPECT_EQ(bundleStructureGrid(smallGrid({7, 5, 4}, 0.5), 2).size, glm::uvec3(4, 3, 2));  // ceil: partial last cells
  const BundleGrid g = smallGrid({8, 6, 4}, 0.5);
  const glm::dvec3 a(0.3, -1.2, 0.7);
  std::vector<double> density(g.voxelCount());
  for (uint32_t z = 0; z < g.size.z; ++z)
    for (uint32_t y = 0; y < g.size.y; ++y)
      for (uint32_t x = 0; x < g.size.x; ++x) density[g.index(x, y, z)] = 5 + glm::dot(a, glm::dvec3(x, y, z) * 0.5);
  const BundleGrid cells = bundleStructureGrid(g, 2);
  ASSERT_EQ(cells.size, glm::uvec3(4, 3, 2));
  EXPECT_DOUBLE_EQ(cells.voxel, 1.0);
  const BundleTensors t = structureTensorReference(density, g, 2);
  ASSERT_EQ(t.size(), 24u);
  const glm::dmat3 expected = glm::outerProduct(a, a);
  for (size_t c = 0; c < t.size(); ++c) EXPECT_LT(maxEntry(t[c] - expected), 1e-12) << c;
  // Between cell centres the tensor is trilinear: halfway between two.
  const glm::dvec3 c0 = cells.origin + cells.voxel * glm::dvec3(0.5, 0.5, 0.5);
  const glm::dmat3 mid = interpolateTensor(t, cells, c0 + glm::dvec3(cells.voxel / 2, 0, 0));
  EXPECT_LT(maxEntry(mid - 0.5 * (t[cells.index(0, 0, 0)] + t[cells.index(1, 0, 0)])), 1e-15);
}

TEST(Bundling, structureTensorOfASheetPointsAcrossItEvenAtItsMiddle) {
  // A density that varies in z only (a sheet at z = 4.5 voxels), with a
  // ripple along y finer than the cells: the tensor is zz only, also in the
  // middle cell where the cell-mean gradient is zero.
  const BundleGrid g = smallGrid({8, 8, 9}, 1.0);
  std::vector<double> density(g.voxelCount());
  for (uint32_t z = 0; z < g.size.z; ++z)
    for (uint32_t y = 0; y < g.size.y; ++y)
      for (uint32_t x = 0; x < g.size.x; ++x)
        density[g.index(x, y, z)] = std::max(0.0, 16 - (z + 0.5 - 4.5) * (z + 0.5 - 4.5)) + (y % 2 ? 1.0 : 0.0);
  const BundleTensors t = structureTensorReference(density, g, 2);
  const BundleGrid cells = bundleStructureGrid(g, 2);
  for (uint32_t cz = 0; cz < cells.size.z; ++cz) {
    const glm::dmat3& j = t[cells.index(1, 1, cz)];
    EXPECT_GT(j[2][2], 1.0) << cz;
    EXPECT_LT(std::abs(j[0][0]) + std::abs(j[1][1]) + std::abs(j[0][1]) + std::abs(j[1][2]) + std::abs(j[0][2]), 1e-12)
        << cz;
  }
}

TEST(Bundling, structureAwareAdvectionStepsAcrossASheetOnly) {
  // A uniform gradient (0, 1, 1) and a sheet's tensor (gradients along z):
  // the plain step goes diagonally, the filtered one along z, by the
  // filter's formula.
  const BundleGrid g = smallGrid({6, 6, 6}, 1.0);
  const std::vector<glm::dvec3> grad(g.voxelCount(), glm::dvec3(0, 1, 1));
  const BundleTensors sheet(8, glm::dmat3(glm::dvec3(0.01, 0, 0), glm::dvec3(0, 0.01, 0), glm::dvec3(0, 0, 1)));
  const BundleStructureField field{&sheet, bundleStructureGrid(g, 3), 2};
  const BundleSamples s = line(g.origin + glm::dvec3(1, 3, 3), glm::dvec3(1, 0, 0), 4, 1.0);
  const std::vector<uint32_t> offsets = {0, 4};
  const BundleSamples plain = advectReference(s, offsets, grad, g, 1.0, false);
  const BundleSamples aware = advectReference(s, offsets, grad, g, 1.0, false, &field);
  const double r2 = std::sqrt(2.0);
  for (size_t i = 0; i < s.size(); ++i) {
    EXPECT_NEAR(glm::length(plain[i] - s[i] - glm::dvec3(0, 1, 1) / r2), 0, 1e-12);
    EXPECT_NEAR(glm::length(aware[i] - s[i] - glm::dvec3(0, 1e-4, 1) / r2), 0, 1e-12);
  }
}

TEST(Bundling, structureAwareModeKeepsASheetFromBreakingIntoStrands) {
  const Tractogram t = sheetModel(24, 7);
  BundleParams p = fineParams(4, 8);
  const std::vector<float> iso = bundleReference(t, p);
  p.structure_aware = true;
  const std::vector<float> aware = bundleReference(t, p);
  // Mean |motion| in the sheet's plane (y) and across it (z), middle points
  // of the inner fibers (the sheet's edges move in both).
  auto motion = [&](const std::vector<float>& out, int axis) {
    double sum = 0;
    int n = 0;
    for (size_t f = 3; f + 3 < t.streamlineCount(); ++f) {
      const uint64_t i = t.offsets[f] + 20;
      sum += std::abs(out[3 * i + axis] - t.positions[3 * i + axis]);
      ++n;
    }
    return sum / n;
  };
  // Measured: isotropic y 0.99 mm, z 0.27; structure-aware y 0.014, z 0.20
  // (defaults: scale 1, power 2). The sheet thins, its fibers stay in line.
  EXPECT_LT(motion(aware, 1), 0.1 * motion(iso, 1));
  EXPECT_GT(motion(aware, 2), 0.5 * motion(iso, 2));
}

}  // namespace fibscope
