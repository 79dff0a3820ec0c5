// Cut meshes (select/cut_mesh.h) against analytic shapes: the box mesh's
// inside test is the box's, the icosphere lies in the stated shell of the
// sphere, closure and orientation are detected, and ray hits are the
// analytic ray-box and ray-sphere distances.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <random>

#include "core/error.h"
#include "select/cut_mesh.h"
#include "select/region.h"
#include "test_support.h"

namespace fibscope {
namespace {

glm::vec3 randomIn(std::mt19937& rng, glm::vec3 lo, glm::vec3 hi) {
  std::uniform_real_distribution<float> u(0, 1);
  return lo + glm::vec3(u(rng), u(rng), u(rng)) * (hi - lo);
}

glm::vec3 randomDirection(std::mt19937& rng) {
  std::normal_distribution<float> n(0, 1);
  return glm::normalize(glm::vec3(n(rng), n(rng), n(rng)));
}

// The ray's parameters where it enters and leaves the box (slab method).
bool rayBox(glm::dvec3 o, glm::dvec3 d, glm::dvec3 lo, glm::dvec3 hi, double& t_in, double& t_out) {
  t_in = -INFINITY, t_out = INFINITY;
  for (int k = 0; k < 3; ++k) {
    const double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
    t_in = std::max(t_in, std::min(a, b));
    t_out = std::min(t_out, std::max(a, b));
  }
  return t_in <= t_out;
}

// The ray's parameters on the sphere |p - c| = r (unit d).
bool raySphere(glm::dvec3 o, glm::dvec3 d, glm::dvec3 c, double r, double& t_in, double& t_out) {
  const double b = glm::dot(o - c, d), q = glm::dot(o - c, o - c) - r * r, disc = b * b - q;
  if (disc < 0) return false;
  t_in = -b - std::sqrt(disc), t_out = -b + std::sqrt(disc);
  return true;
}

TEST(CutMesh, boxMeshInsideIsTheAnalyticBoxAwayFromItsFaces) {
  const auto box = std::get<BoxRegion>(parseRegion("box:-3,-1,2,5,4,2.5"));
  const TriangleMesh mesh = makeBoxMesh(box);
  EXPECT_EQ(mesh.positions.size(), 8u);
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_NEAR(meshVolume(mesh), 8.0 * 5.0 * 0.5, 1e-9);
  std::mt19937 rng(1);
  int inside = 0, tested = 0;
  for (int i = 0; i < 4000; ++i) {
    const glm::vec3 p = randomIn(rng, {-4, -2, 1.5f}, {6, 5, 3});
    bool near_face = false;
    for (int k = 0; k < 3; ++k) near_face |= std::fabs(p[k] - box.min[k]) < 1e-3 || std::fabs(p[k] - box.max[k]) < 1e-3;
    if (near_face) continue;
    const bool expected = regionContains(box, &p.x);
    EXPECT_EQ(pointInsideMesh(mesh, p), expected) << p.x << " " << p.y << " " << p.z;
    inside += expected, ++tested;
  }
  EXPECT_GT(inside, 200);
  EXPECT_GT(tested - inside, 200);
}

TEST(CutMesh, orientedBoxMeshInsideIsTheAnalyticOrientedBox) {
  const auto obox = std::get<OrientedBoxRegion>(parseRegion("obox:1,2,3,10,4,2,30,-20,75"));
  const TriangleMesh mesh = makeBoxMesh(obox);
  EXPECT_NEAR(meshVolume(mesh), 10.0 * 4.0 * 2.0, 1e-4);
  EXPECT_TRUE(checkClosure(mesh).closed());
  std::mt19937 rng(2);
  int inside = 0, tested = 0;
  for (int i = 0; i < 4000; ++i) {
    const glm::vec3 p = randomIn(rng, {-5, -4, -3}, {7, 8, 9});
    bool near_face = false;
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3 axis(obox.axes[k][0], obox.axes[k][1], obox.axes[k][2]);
      const double along = glm::dot(glm::dvec3(p) - glm::dvec3(1, 2, 3), axis);
      near_face |= std::fabs(std::fabs(along) - obox.half[k]) < 1e-3;
    }
    if (near_face) continue;
    const bool expected = regionContains(obox, &p.x);
    EXPECT_EQ(pointInsideMesh(mesh, p), expected);
    inside += expected, ++tested;
  }
  EXPECT_GT(inside, 100);
  EXPECT_GT(tested - inside, 100);
}

TEST(CutMesh, icosphereLiesInTheStatedShellOfTheSphere) {
  const glm::vec3 c(10, -20, 30);
  const float r = 25;
  std::mt19937 rng(3);
  for (int s = 0; s <= 5; ++s) {
    SCOPED_TRACE(s);
    const TriangleMesh mesh = makeSphereMesh(c, r, s);
    EXPECT_EQ(mesh.triangles.size(), 20u << (2 * s));
    EXPECT_TRUE(checkClosure(mesh).closed());
    for (const glm::vec3& p : mesh.positions) EXPECT_NEAR(glm::distance(p, c), r, 2e-6 * r);
    const double theta = sphereMeshAngle(s), inner = r * std::cos(theta);
    // The bound holds and is tight: each face's plane is at least r cos theta
    // from the centre, and the nearest one within a few percent of the angle.
    double closest = r;
    for (const glm::uvec3& t : mesh.triangles) {
      const glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], cc = mesh.positions[t.z];
      const glm::dvec3 n = glm::normalize(glm::cross(b - a, cc - a));
      closest = std::min(closest, glm::dot(n, a - glm::dvec3(c)));  // > 0: outward
    }
    EXPECT_GE(closest, inner * (1 - 1e-6));
    EXPECT_GT(std::acos(std::min(1.0, closest / r)), 0.9 * theta);
    const double full = 4.0 / 3.0 * glm::pi<double>() * r * r * r;
    EXPECT_LE(meshVolume(mesh), full);
    EXPECT_GE(meshVolume(mesh), full * std::pow(std::cos(theta), 3));
    if (s > 3) continue;  // the point test is O(triangles) per point
    int in = 0, out = 0;
    for (int i = 0; i < 1500; ++i) {
      const glm::vec3 p = randomIn(rng, c - 1.2f * r, c + 1.2f * r);
      const double d = glm::distance(glm::dvec3(p), glm::dvec3(c));
      if (d < inner * (1 - 1e-5)) {
        EXPECT_TRUE(pointInsideMesh(mesh, p)) << d;
        ++in;
      } else if (d > r * (1 + 1e-5)) {
        EXPECT_FALSE(pointInsideMesh(mesh, p)) << d;
        ++out;
      }
    }
    EXPECT_GT(in, 200);
    EXPECT_GT(out, 200);
  }
  EXPECT_LT(1 - std::cos(sphereMeshAngle(kCutSphereSubdivisions)), 1.2e-3);
}

TEST(CutMesh, closureFindsOpenNonManifoldAndFlippedEdges) {
  TriangleMesh box = makeBoxMesh(std::get<BoxRegion>(parseRegion("box:0,0,0,1,2,3")));
  MeshClosure c = checkClosure(box);
  EXPECT_TRUE(c.closed());
  EXPECT_EQ(c.edges, 18u);
  EXPECT_EQ(closureWarning(c, "box"), "");

  TriangleMesh open = box;
  open.triangles.pop_back();
  c = checkClosure(open);
  EXPECT_FALSE(c.closed());
  EXPECT_EQ(c.open_edges, 3u);  // the edges of the missing triangle
  const std::string warning = closureWarning(c, "open.obj");
  EXPECT_EQ(warning.rfind("open.obj: not closed (3 open edges", 0), 0u) << warning;
  EXPECT_NE(warning.find("the cut may be approximate"), std::string::npos);
  EXPECT_EQ(warning.find('\n'), std::string::npos);

  TriangleMesh flipped = box;
  std::swap(flipped.triangles[4].y, flipped.triangles[4].z);
  c = checkClosure(flipped);
  EXPECT_EQ(c.inconsistent_edges, 3u);
  EXPECT_EQ(c.open_edges + c.non_manifold_edges, 0u);

  TriangleMesh doubled = box;
  doubled.triangles.push_back(doubled.triangles[0]);
  EXPECT_EQ(checkClosure(doubled).non_manifold_edges, 3u);

  // A corner repeated per triangle (as STL-converted OBJs do) is welded.
  TriangleMesh soup;
  for (const glm::uvec3& t : box.triangles) {
    const uint32_t base = uint32_t(soup.positions.size());
    for (const uint32_t v : {t.x, t.y, t.z}) soup.positions.push_back(box.positions[v]);
    soup.triangles.emplace_back(base, base + 1, base + 2);
  }
  EXPECT_TRUE(checkClosure(soup).closed());
  soup.triangles.emplace_back(0, 0, 1);
  EXPECT_EQ(checkClosure(soup).degenerate_triangles, 1u);
}

TEST(CutMesh, inwardMeshesAreTurnedOutward) {
  TriangleMesh box = makeBoxMesh(std::get<BoxRegion>(parseRegion("box:0,0,0,2,2,2")));
  EXPECT_FALSE(orientOutward(box));
  for (glm::uvec3& t : box.triangles) std::swap(t.x, t.y);
  EXPECT_NEAR(meshVolume(box), -8, 1e-9);
  EXPECT_NEAR(windingNumber(box, {1, 1, 1}), -1, 1e-9);
  EXPECT_TRUE(pointInsideMesh(box, {1, 1, 1})) << "inside whatever the orientation";
  EXPECT_TRUE(orientOutward(box));
  EXPECT_NEAR(meshVolume(box), 8, 1e-9);
  EXPECT_NEAR(windingNumber(box, {1, 1, 1}), 1, 1e-9);
  EXPECT_NEAR(windingNumber(box, {3, 1, 1}), 0, 1e-9);
}

TEST(CutMesh, rayHitsAreTheAnalyticRayBoxDistancesWithTheirFacing) {
  const glm::dvec3 lo(-2, -1, 0), hi(3, 1, 4);
  const TriangleMesh box = makeBoxMesh(std::get<BoxRegion>(parseRegion("box:-2,-1,0,3,1,4")));
  std::mt19937 rng(4);
  int two = 0, one = 0, none = 0;
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 o = randomIn(rng, {-6, -5, -4}, {7, 5, 8}), d = randomDirection(rng) * 3.0f;  // any length
    const glm::dvec3 unit = glm::normalize(glm::dvec3(d));
    double t_in = 0, t_out = 0;
    std::vector<std::pair<double, bool>> expected;
    if (rayBox(o, unit, lo, hi, t_in, t_out)) {
      if (t_in >= 0) expected.emplace_back(t_in, true);
      if (t_out >= 0) expected.emplace_back(t_out, false);
    }
    const std::vector<MeshHit> hits = rayMeshHits(box, o, d);
    ASSERT_EQ(hits.size(), expected.size()) << i;
    for (size_t k = 0; k < hits.size(); ++k) {
      EXPECT_NEAR(hits[k].distance, expected[k].first, 1e-4);
      EXPECT_EQ(hits[k].front, expected[k].second);
    }
    (expected.size() == 2 ? two : expected.size() == 1 ? one : none)++;
  }
  EXPECT_GT(two, 100);
  EXPECT_GT(one, 50);  // from inside
  EXPECT_GT(none, 100);
  EXPECT_TRUE(rayMeshHits(box, {0, 0, 2}, {0, 0, 0}).empty());
}

TEST(CutMesh, rayHitsOnTheIcosphereLieBetweenItsInnerAndOuterSpheres) {
  const glm::dvec3 c(1, 2, 3);
  const double r = 10;
  const int s = 3;
  const TriangleMesh sphere = makeSphereMesh(c, float(r), s);
  const double inner = r * std::cos(sphereMeshAngle(s));
  std::mt19937 rng(5);
  int crossing = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 o = randomIn(rng, glm::vec3(c) - 20.0f, glm::vec3(c) + 20.0f), d = randomDirection(rng);
    if (glm::distance(glm::dvec3(o), c) <= r) continue;
    const std::vector<MeshHit> hits = rayMeshHits(sphere, o, d);
    double out_in = 0, out_out = 0, in_in = 0, in_out = 0;
    if (!raySphere(o, d, c, r, out_in, out_out) || out_out < 0) {
      EXPECT_TRUE(hits.empty());
      continue;
    }
    if (!raySphere(o, d, c, inner, in_in, in_out)) continue;  // grazing: between the two spheres
    ++crossing;
    ASSERT_EQ(hits.size(), 2u);
    EXPECT_TRUE(hits[0].front);
    EXPECT_FALSE(hits[1].front);
    EXPECT_GE(hits[0].distance, out_in - 1e-4);
    EXPECT_LE(hits[0].distance, in_in + 1e-4);
    EXPECT_GE(hits[1].distance, in_out - 1e-4);
    EXPECT_LE(hits[1].distance, out_out + 1e-4);
  }
  EXPECT_GT(crossing, 100);
}

TEST(CutMesh, specsNameBuiltInShapesOrObjFiles) {
  EXPECT_TRUE(isBuiltinMeshSpec("box:0,0,0,1,1,1"));
  EXPECT_FALSE(isBuiltinMeshSpec("./box:0,0,0,1,1,1"));
  EXPECT_FALSE(isBuiltinMeshSpec("cut.obj"));
  for (const std::string spec : {"box:0,0,0,1,2,3", "obox:0,0,0,1,2,3,10,20,30", "sphere:0,0,0,5"}) {
    const TriangleMesh mesh = cutMeshFromSpec(spec);
    EXPECT_TRUE(checkClosure(mesh).closed()) << spec;
    EXPECT_GT(meshVolume(mesh), 0) << spec;
  }
  EXPECT_EQ(cutMeshFromSpec("sphere:0,0,0,5").triangles.size(), 20u << (2 * kCutSphereSubdivisions));
  for (const std::string spec : {"box:0,0,0,1", "sphere:0,0,0,-1", "obox:0,0,0,0,1,1,0,0,0"}) {
    const std::string message = test::errorOf([&] { cutMeshFromSpec(spec); });
    EXPECT_EQ(message.rfind(spec + ": ", 0), 0u) << message;
  }
  // An OBJ box wound inward, under a name with ':' in it, comes back outward.
  test::TempDir dir;
  const std::string path = dir.file("left:cut.obj");
  std::string text;
  const TriangleMesh box = makeBoxMesh(std::get<BoxRegion>(parseRegion("box:0,0,0,1,1,1")));
  for (const glm::vec3& p : box.positions)
    text += "v " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z) + "\n";
  for (const glm::uvec3& t : box.triangles)
    text += "f " + std::to_string(t.x + 1) + " " + std::to_string(t.z + 1) + " " + std::to_string(t.y + 1) + "\n";
  test::writeBytes(path, text);
  EXPECT_NEAR(meshVolume(loadObjMesh(path)), -1, 1e-6);
  EXPECT_NEAR(meshVolume(cutMeshFromSpec(path)), 1, 1e-6);
  const std::string missing = test::errorOf([&] { cutMeshFromSpec(dir.file("none.obj")); });
  EXPECT_EQ(missing.rfind(dir.file("none.obj") + ": ", 0), 0u) << missing;
}

}  // namespace
}  // namespace fibscope
