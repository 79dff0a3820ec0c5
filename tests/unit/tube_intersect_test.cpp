// The ray casting of sphere-swept quadratic tubes on the CPU
// (src/tubes/tube_intersect.h): the bisection cascade against analytic
// cylinders and spheres, and whole frames of curved test tubes (a tight
// 90 degree turn, a varying radius, an S-curve) against the independent
// brute-force sphere sweep, from several views.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "shared/render_config.h"
#include "tube_test_scenes.h"
#include "tubes/tube_intersect.h"

namespace fibscope {
namespace {

shader::TubeQuadratic straight(glm::vec3 a, glm::vec3 b, float r0, float r1) {
  const glm::vec3 m = 0.5f * (a + b);
  return {{a.x, a.y, a.z, r0}, {m.x, m.y, m.z, 0.5f * (r0 + r1)}, {b.x, b.y, b.z, r1}};
}

TEST(TubeIntersect, aStraightConstantRadiusSubSegmentIsACylinderWithSphericalEnds) {
  const shader::TubeQuadratic q = straight({-5, 0, 0}, {5, 0, 0}, 1.0f, 1.0f);
  // Across the axis: the cylinder at distance 10 - 1.
  for (double x : {-4.0, 0.0, 2.5}) {
    const TubeRayHit h = intersectTubeQuadratic(q, {x, 0.3, 10}, {0, 0, -1});
    ASSERT_TRUE(h.hit) << x;
    EXPECT_NEAR(h.distance, 10 - std::sqrt(1 - 0.09), 1e-7) << x;
    EXPECT_NEAR(h.t, (x + 5) / 10, 2e-3) << x;
    EXPECT_NEAR(h.normal.y, 0.3, 1e-6);
  }
  // Along the axis: the end sphere.
  const TubeRayHit end = intersectTubeQuadratic(q, {20, 0.5, 0}, {-1, 0, 0});
  ASSERT_TRUE(end.hit);
  EXPECT_NEAR(end.distance, 15 - std::sqrt(1 - 0.25), 1e-9);
  EXPECT_EQ(end.t, 1.0);
  // Misses: beside it, beyond its end, behind the origin.
  EXPECT_FALSE(intersectTubeQuadratic(q, {0, 1.01, 10}, {0, 0, -1}).hit);
  EXPECT_FALSE(intersectTubeQuadratic(q, {6.2, 0, 10}, {0, 0, -1}).hit);
  EXPECT_FALSE(intersectTubeQuadratic(q, {0, 0, 10}, {0, 0, 1}).hit);
}

TEST(TubeIntersect, aConeOfLinearRadiusIsHitWhereItsSurfaceIs) {
  // Radius 0.5 -> 1.5 along x over 10 mm: seen from +z across the axis at
  // x, the swept spheres' envelope is a cone with half-angle asin(0.1).
  const shader::TubeQuadratic q = straight({0, 0, 0}, {10, 0, 0}, 0.5f, 1.5f);
  for (double x : {2.0, 5.0, 8.0}) {
    const TubeRayHit h = intersectTubeQuadratic(q, {x, 0, 10}, {0, 0, -1});
    const TubeRayHit b = intersectTubeQuadraticBruteForce(q, {x, 0, 10}, {0, 0, -1});
    ASSERT_TRUE(h.hit && b.hit);
    EXPECT_NEAR(h.distance, b.distance, 1e-6) << x;
    // The envelope touches sphere t where its normal is tilted back by the
    // cone's angle: the hit height is r(t) / cos, the spheres' centre t
    // shifted forward by r dr/ds.
    const double slope = 0.1, r_at = 0.5 + slope * x;
    EXPECT_NEAR(10 - h.distance, r_at / std::sqrt(1 - slope * slope), 1e-5) << x;
  }
}

// Hit/miss and distance per pixel of two frames of the same tubes.
struct FrameAgreement {
  size_t either = 0, disagree = 0, both = 0, fiber_mismatch = 0;
  double max_distance_error = 0;
  double agreement() const { return either ? 1.0 - double(disagree) / double(either) : 1.0; }
};

FrameAgreement compareFrames(const TubeReferenceImage& a, const TubeReferenceImage& b) {
  FrameAgreement r;
  for (size_t i = 0; i < a.fiber.size(); ++i) {
    const bool ha = a.fiber[i] != shader::kNoFiberId, hb = b.fiber[i] != shader::kNoFiberId;
    if (!ha && !hb) continue;
    ++r.either;
    if (ha != hb) {
      ++r.disagree;
      continue;
    }
    ++r.both;
    if (a.fiber[i] != b.fiber[i]) ++r.fiber_mismatch;
    r.max_distance_error = std::max(r.max_distance_error, std::fabs(a.distance[i] - b.distance[i]));
  }
  return r;
}

TEST(TubeIntersect, cascadeFramesAgreeWithTheBruteForceSphereSweepOnCurvedTubes) {
  for (const test::TubeScene& scene : test::tubeScenes()) {
    const TubeModel model = buildTubes(scene.tractogram, scene.options);
    for (const Camera& camera : test::tubeSceneCameras(scene, 96, 72)) {
      const TubeReferenceImage cascade = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
      const TubeReferenceImage brute = renderReferenceTubes(model, camera, TubeReferenceMethod::BruteForce, 1024);
      const FrameAgreement a = compareFrames(cascade, brute);
      const std::string what = scene.name + " from (" + std::to_string(camera.eye[0]) + ", " +
                               std::to_string(camera.eye[1]) + ", " + std::to_string(camera.eye[2]) + ")";
      EXPECT_GT(a.both, 150u) << what;
      EXPECT_GE(a.agreement(), 0.98) << what << ": " << a.disagree << " of " << a.either;
      // The bound: within 1e-4 of the radius.
      EXPECT_LE(a.max_distance_error, 1e-4 * scene.min_radius) << what;
      // Where two fibers overlap in depth within that bound either may win.
      EXPECT_LE(a.fiber_mismatch, a.both / 200) << what;
    }
  }
}

}  // namespace
}  // namespace fibscope
