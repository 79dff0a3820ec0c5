// The tube model (src/tubes/tube_model.h, tube_frames.h): Hermite segments
// through the nodes with the nodes' derivatives, the quadratic split,
// radius sources, rotation-minimising frames against analytic and
// independent references, resampling within its tolerance measured
// densely against the original polyline.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "core/error.h"
#include "tubes/tube_frames.h"
#include "tubes/tube_intersect.h"
#include "tubes/tube_model.h"

namespace fibscope {
namespace {

glm::vec3 nodePosition(const shader::TubeNode& n) {
  return {n.position_radius.x, n.position_radius.y, n.position_radius.z};
}
glm::vec3 nodeTangent(const shader::TubeNode& n) {
  return {n.tangent_dradius.x, n.tangent_dradius.y, n.tangent_dradius.z};
}

// A random walk of `n` steps of `step` mm turning at most `max_turn_deg`
// per step (tracker-like).
std::vector<float> randomCurve(std::mt19937& rng, size_t n, float step, float max_turn_deg) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> xyz;
  glm::vec3 p(0.0f), d = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
  const float max_turn = std::sin(max_turn_deg * std::numbers::pi_v<float> / 180.0f);
  for (size_t i = 0; i < n; ++i) {
    xyz.insert(xyz.end(), {p.x, p.y, p.z});
    glm::vec3 q(u(rng), u(rng), u(rng));
    q -= glm::dot(q, d) * d;
    if (glm::length(q) > 1e-6f) d = glm::normalize(d + max_turn * u(rng) * glm::normalize(q));
    p += step * d;
  }
  return xyz;
}

Tractogram oneFiber(const std::vector<float>& xyz) {
  Tractogram t;
  t.addStreamline(xyz.data(), xyz.size() / 3);
  return t;
}

TEST(TubeModel, hermiteSegmentsPassThroughTheirNodesWithTheNodeDerivatives) {
  std::mt19937 rng(7);
  const std::vector<float> xyz = randomCurve(rng, 200, 0.5f, 25.0f);
  const TubeModel model = buildTubes(oneFiber(xyz), {});
  ASSERT_EQ(model.nodes.size(), 200u);
  ASSERT_EQ(model.segments.size(), 199u);
  for (const shader::TubeSegment& s : model.segments) {
    const shader::TubeNode &a = model.nodes[s.node], &b = model.nodes[s.node + 1];
    EXPECT_LT(glm::distance(tubeSegmentPoint(model, s, 0.0f), nodePosition(a)), 1e-5f);
    EXPECT_LT(glm::distance(tubeSegmentPoint(model, s, 1.0f), nodePosition(b)), 1e-5f);
    EXPECT_NEAR(s.chord, glm::distance(nodePosition(a), nodePosition(b)), 1e-5f);
    // The derivative is the node tangent (per mm) times the chord, and a
    // finite difference of the curve agrees with it.
    const glm::vec3 m0 = s.chord * nodeTangent(a), m1 = s.chord * nodeTangent(b);
    EXPECT_LT(glm::distance(tubeSegmentDerivative(model, s, 0.0f), m0), 1e-5f);
    EXPECT_LT(glm::distance(tubeSegmentDerivative(model, s, 1.0f), m1), 1e-5f);
    // (Central differences: the cubic extends past [0, 1].)
    const float h = 1e-2f;
    const glm::vec3 fd0 = (tubeSegmentPoint(model, s, h) - tubeSegmentPoint(model, s, -h)) / (2 * h);
    const glm::vec3 fd1 = (tubeSegmentPoint(model, s, 1.0f + h) - tubeSegmentPoint(model, s, 1.0f - h)) / (2 * h);
    EXPECT_LT(glm::distance(fd0, m0), 1e-3f);
    EXPECT_LT(glm::distance(fd1, m1), 1e-3f);
    EXPECT_NEAR(glm::length(nodeTangent(a)), 1.0f, 1e-5f);
  }
}

TEST(TubeModel, quadraticSubSegmentsJoinAtTheCubicsMidpointAndFollowTheNodeTangents) {
  std::mt19937 rng(11);
  const TubeModel model = buildTubes(oneFiber(randomCurve(rng, 50, 1.0f, 40.0f)), {});
  for (uint32_t k = 0; k < model.segments.size(); ++k) {
    const shader::TubeSegment& s = model.segments[k];
    const shader::TubeQuadratic q0 = tubeSubSegment(model, 2 * k), q1 = tubeSubSegment(model, 2 * k + 1);
    const glm::dvec3 p0 = tubeQuadraticCenter(q0, 0), mid0 = tubeQuadraticCenter(q0, 1),
                     mid1 = tubeQuadraticCenter(q1, 0), p1 = tubeQuadraticCenter(q1, 1);
    EXPECT_LT(glm::distance(glm::vec3(p0), nodePosition(model.nodes[s.node])), 1e-5f);
    EXPECT_LT(glm::distance(glm::vec3(p1), nodePosition(model.nodes[s.node + 1])), 1e-5f);
    EXPECT_LT(glm::distance(mid0, mid1), 1e-6);
    EXPECT_LT(glm::distance(glm::vec3(mid0), tubeSegmentPoint(model, s, 0.5f)), 1e-5f);
    // Start and end directions are the node tangents.
    const glm::vec3 d0 = glm::normalize(glm::vec3(q0.b1.x - q0.b0.x, q0.b1.y - q0.b0.y, q0.b1.z - q0.b0.z));
    const glm::vec3 d1 = glm::normalize(glm::vec3(q1.b2.x - q1.b1.x, q1.b2.y - q1.b1.y, q1.b2.z - q1.b1.z));
    EXPECT_GT(glm::dot(d0, nodeTangent(model.nodes[s.node])), 1.0f - 1e-5f);
    EXPECT_GT(glm::dot(d1, nodeTangent(model.nodes[s.node + 1])), 1.0f - 1e-5f);
  }
}

TEST(TubeModel, perPointRadiusIsMappedOverItsRangeClampedAndNanTakesTheMinimum) {
  Tractogram t = oneFiber({0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 4, 0, 0});
  t.per_point.push_back({"fa", 1, "float32", {0.0f, 0.5f, 1.0f, 7.0f, std::numeric_limits<float>::quiet_NaN()}});
  TubeBuildOptions o;
  o.radius.source = TubeRadius::Source::PerPoint;
  o.radius.array = "fa";
  o.radius.data_min = 0.0f;
  o.radius.data_max = 1.0f;
  o.radius.radius_min = 0.2f;
  o.radius.radius_max = 1.0f;
  TubeBuildStats stats;
  const TubeModel model = buildTubes(t, o, &stats);
  ASSERT_EQ(model.nodes.size(), 5u);
  const float want[] = {0.2f, 0.6f, 1.0f, 1.0f, 0.2f};
  for (int i = 0; i < 5; ++i) EXPECT_FLOAT_EQ(model.nodes[i].position_radius.w, want[i]) << i;
  EXPECT_EQ(stats.invalid_radii, 1u);
  // dr/ds: central difference over the two chords of 1 mm.
  EXPECT_NEAR(model.nodes[1].tangent_dradius.w, (1.0f - 0.2f) / 2.0f, 1e-6f);
  EXPECT_NEAR(model.nodes[0].tangent_dradius.w, 0.4f, 1e-6f);
}

TEST(TubeModel, badRadiusOptionsAreErrorsNamingTheProblem) {
  const Tractogram t = oneFiber({0, 0, 0, 1, 0, 0});
  TubeBuildOptions o;
  o.radius.radius = 0.0f;
  EXPECT_THROW(buildTubes(t, o), Error);
  o.radius.radius = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(buildTubes(t, o), Error);
  o = {};
  o.radius.source = TubeRadius::Source::PerFiber;
  o.radius.array = "missing";
  try {
    buildTubes(t, o);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
  o = {};
  o.fibers = {3};
  EXPECT_THROW(buildTubes(t, o), Error);
  o = {};
  o.resample_tolerance = -1.0f;
  EXPECT_THROW(buildTubes(t, o), Error);
}

TEST(TubeModel, aFiberOfOnePointIsASphereAndRepeatedPointsAreDropped) {
  Tractogram t;
  const float one[] = {1, 2, 3};
  t.addStreamline(one, 1);
  const float repeated[] = {0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0};
  t.addStreamline(repeated, 4);
  TubeBuildStats stats;
  const TubeModel model = buildTubes(t, {}, &stats);
  ASSERT_EQ(model.tubes.size(), 2u);
  EXPECT_EQ(model.tubes[0].node_count, 2u);  // the point twice
  EXPECT_EQ(model.tubes[1].node_count, 2u);
  ASSERT_EQ(model.segments.size(), 2u);
  EXPECT_EQ(model.segments[0].chord, 0.0f);
  EXPECT_EQ(stats.single_point_tubes, 1u);
  EXPECT_EQ(stats.duplicate_points, 2u);
  EXPECT_EQ(model.nodes[3].point, 2.0f);  // the second distinct point was point 2 of the fiber
  // The one-point tube's sub-segments are its sphere: hit where a sphere of
  // radius 0.5 at (1, 2, 3) is, by the cascade.
  for (uint32_t half : {0u, 1u}) {
    const TubeRayHit h = intersectTubeQuadratic(tubeSubSegment(model, half), {1.2, 2.1, 13}, {0, 0, -1});
    ASSERT_TRUE(h.hit);
    EXPECT_NEAR(h.distance, 10 - std::sqrt(0.25 - 0.05), 1e-6);
  }
  EXPECT_FALSE(intersectTubeQuadratic(tubeSubSegment(model, 0), {1.5, 2.1, 13}, {0, 0, -1}).hit);
}

// Frames on a helix of radius a and pitch 2 pi b: the rotation-minimising
// frame turns against the Frenet frame at minus the torsion per mm,
// theta(s) = theta(0) - tau s, tau = b / (a^2 + b^2).
TEST(TubeFrames, framesStayOrthonormalAndTurnAgainstTheHelixFrenetFrameByItsTorsion) {
  const double a = 8.0, b = 3.0, c = std::sqrt(a * a + b * b), tau = b / (c * c), step = 0.25;
  const size_t n = 1600;  // 400 mm, about 8 turns
  std::vector<float> xyz;
  for (size_t i = 0; i < n; ++i) {
    const double s = step * double(i), phi = s / c;
    xyz.insert(xyz.end(), {float(a * std::cos(phi)), float(a * std::sin(phi)), float(b * phi)});
  }
  const TubeModel model = buildTubes(oneFiber(xyz), {});
  ASSERT_EQ(model.nodes.size(), n);
  double theta0 = 0, worst = 0;
  for (size_t i = 0; i < n; ++i) {
    const double s = step * double(i), phi = s / c;
    const glm::dvec3 tangent = glm::dvec3(-a * std::sin(phi), a * std::cos(phi), b) / c;
    const glm::dvec3 normal(-std::cos(phi), -std::sin(phi), 0.0);  // Frenet N
    const glm::dvec3 binormal = glm::cross(tangent, normal);
    const glm::dvec3 r = glm::dvec3(unpackUnitVector(model.nodes[i].normal));
    ASSERT_NEAR(glm::length(r), 1.0, 1e-5);
    // Normal to the node tangent (the tangent estimated from the points).
    ASSERT_LT(std::fabs(glm::dot(r, glm::dvec3(nodeTangent(model.nodes[i])))), 2e-4) << i;
    const double theta = std::atan2(glm::dot(r, binormal), glm::dot(r, normal));
    if (i == 0) theta0 = theta;
    double e = theta - (theta0 - tau * s);
    e = std::remainder(e, 2 * std::numbers::pi);
    worst = std::max(worst, std::fabs(e));
  }
  // 400 mm of helix; tau s = 16.4 rad of accumulated rotation (measured
  // error: 0.003 degrees).
  EXPECT_LT(worst * 180 / std::numbers::pi, 0.05) << "twist error " << worst * 180 / std::numbers::pi << " deg";
}

// A tight turn out of the plane (consecutive tangents 60 - 90 degrees
// apart): the propagated frame with sub-steps agrees with an independent
// dense rotation-minimising frame along the same Hermite curve (projection
// of the frame onto each new normal plane, 20,000 steps a segment), and
// single steps (no sub-steps) do worse.
TEST(TubeFrames, subStepsFollowTheDenseRotationMinimisingFrameAcrossATightTurn) {
  // Chords turning by 80 - 100 degrees, out of any one plane.
  std::vector<float> xyz;
  glm::vec3 p(0.0f);
  for (const glm::vec3& d : {glm::vec3(1, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0.3f), glm::vec3(-1, 0.2f, 0.5f),
                             glm::vec3(0, -1, 0.6f), glm::vec3(1, 0, 0.4f), glm::vec3(1, 0, 0)}) {
    xyz.insert(xyz.end(), {p.x, p.y, p.z});
    p += glm::normalize(d);
  }
  xyz.insert(xyz.end(), {p.x, p.y, p.z});
  const Tractogram t = oneFiber(xyz);
  TubeBuildOptions stepped, single;
  single.frame_substep_degrees = 180.0f;
  const TubeModel with = buildTubes(t, stepped), without = buildTubes(t, single);
  // The reference frame along the Hermite curve of `with` (same nodes).
  glm::dvec3 r = glm::dvec3(unpackUnitVector(with.nodes[0].normal));
  double worst_with = 0, worst_without = 0, max_turn = 0;
  for (const shader::TubeSegment& s : with.segments) {
    max_turn = std::max(
        max_turn,
        std::acos(std::clamp(double(glm::dot(nodeTangent(with.nodes[s.node]), nodeTangent(with.nodes[s.node + 1]))),
                             -1.0, 1.0)));
    constexpr int kSteps = 20000;
    for (int k = 1; k <= kSteps; ++k) {
      const glm::dvec3 d = glm::normalize(glm::dvec3(tubeSegmentDerivative(with, s, float(k) / kSteps)));
      r = glm::normalize(r - glm::dot(r, d) * d);
    }
    const auto angle = [&](uint32_t packed) {
      return std::acos(std::clamp(glm::dot(r, glm::dvec3(unpackUnitVector(packed))), -1.0, 1.0)) * 180 /
             std::numbers::pi;
    };
    worst_with = std::max(worst_with, angle(with.nodes[s.node + 1].normal));
    worst_without = std::max(worst_without, angle(without.nodes[s.node + 1].normal));
  }
  EXPECT_GT(max_turn * 180 / std::numbers::pi, 60.0);
  // Measured: 0.018 degrees with sub-steps, 4.5 without.
  EXPECT_LT(worst_with, 0.1) << "with sub-steps " << worst_with << " deg, single steps " << worst_without << " deg";
  EXPECT_GT(worst_without, 1.0);
}

// Dense distances between the tube's centre line and the original
// polyline, both ways.
double distanceToPolyline(const glm::vec3& q, const std::vector<glm::vec3>& line) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const glm::vec3 a = line[i], ab = line[i + 1] - a;
    const float h = std::clamp(glm::dot(q - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
    best = std::min(best, double(glm::distance(q, a + h * ab)));
  }
  return best;
}

TEST(TubeResample, theCentreLineStaysWithinTheToleranceOfTheOriginalPolylineOnRandomCurves) {
  std::mt19937 rng(2024);
  for (float tolerance : {0.005f, 0.02f, 0.1f}) {
    for (int trial = 0; trial < 4; ++trial) {
      const std::vector<float> xyz = randomCurve(rng, 400, 0.1f, 8.0f);
      TubeBuildOptions o;
      o.resample_tolerance = tolerance;
      TubeBuildStats stats;
      const TubeModel model = buildTubes(oneFiber(xyz), o, &stats);
      std::vector<glm::vec3> original, curve;
      for (size_t i = 0; i < xyz.size() / 3; ++i) original.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
      for (const shader::TubeSegment& s : model.segments)
        for (int k = 0; k < 64; ++k) curve.push_back(tubeSegmentPoint(model, s, float(k) / 64.0f));
      curve.push_back(original.back());
      double worst = 0;
      for (const glm::vec3& q : curve) worst = std::max(worst, distanceToPolyline(q, original));
      for (const glm::vec3& p : original) worst = std::max(worst, distanceToPolyline(p, curve));
      EXPECT_LE(worst, tolerance) << "tolerance " << tolerance << " trial " << trial << ": " << model.nodes.size()
                                  << " nodes";
      // It does resample: fewer nodes for a larger tolerance.
      EXPECT_LT(model.nodes.size(), original.size() * (tolerance >= 0.02f ? 0.25 : 0.6))
          << "tolerance " << tolerance << " worst " << worst;
      EXPECT_EQ(stats.input_points, original.size());
    }
  }
}

}  // namespace
}  // namespace fibscope
