// Cuts (select/cuts.h): the spec text of clip planes, slabs and mesh cuts,
// and the exact segment clipper against dense sampling of the segment.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <random>

#include "core/error.h"
#include "select/cuts.h"
#include "test_support.h"

namespace fibscope {
namespace {

void expectOneLineErrorNaming(const std::string& spec, const std::function<void()>& f) {
  SCOPED_TRACE(spec);
  const std::string message = test::errorOf(f);
  EXPECT_EQ(message.rfind(spec + ": ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(Cuts, clipPlanesKeepTheSideTheirNormalPointsTo) {
  const ClipPlane plane = parseClipPlane("1,2,3,0,0,-4");
  EXPECT_EQ(plane.point, glm::vec3(1, 2, 3));
  EXPECT_EQ(plane.normal, glm::vec3(0, 0, -1)) << "normalised";
  EXPECT_TRUE(planeKeeps(plane, {5, 5, 2}));
  EXPECT_TRUE(planeKeeps(plane, {5, 5, 3})) << "the plane itself is kept";
  EXPECT_FALSE(planeKeeps(plane, {1, 2, 3.01f}));
  const ClipPlane oblique = parseClipPlane("0,0,0,1,1,0");
  EXPECT_NEAR(glm::length(oblique.normal), 1, 1e-7);
  EXPECT_TRUE(planeKeeps(oblique, {1, -0.5f, 7}));
  EXPECT_FALSE(planeKeeps(oblique, {-1, 0.5f, 7}));
  const ClipPlane back = parseClipPlane(clipPlaneSpec(oblique));
  EXPECT_EQ(back.point, oblique.point);
  EXPECT_NEAR(glm::distance(back.normal, oblique.normal), 0, 1e-7);
  for (const std::string spec : {"1,2,3,0,0", "1,2,3,0,0,1,5", "1,2,3,0,0,0", "1,2,nan,0,0,1", "a,b,c,d,e,f",
                                 "1,2,3,0,0,1e39", "", "1,2,3,,0,1"})
    expectOneLineErrorNaming(spec, [&] { parseClipPlane(spec); });
}

TEST(Cuts, slabsHaveAPositiveThicknessAndMayFollowASlice) {
  EXPECT_EQ(parseSlab("5").thickness_mm, 5);
  EXPECT_EQ(parseSlab("5").follow, "");
  const Slab slab = parseSlab("2.5:coronal");
  EXPECT_EQ(slab.thickness_mm, 2.5f);
  EXPECT_EQ(slab.follow, "coronal");
  for (const std::string spec : {"0", "-1", "5:up", "5:", "abc", "", "1e39", ":axial", "5:axial:x"})
    expectOneLineErrorNaming(spec, [&] { parseSlab(spec); });
}

TEST(Cuts, meshCutsNameTheSideCulledAfterTheLastColon) {
  MeshCut cut = parseMeshCut("box:0,0,0,1,1,1:inside");
  EXPECT_EQ(cut.spec, "box:0,0,0,1,1,1");
  EXPECT_TRUE(cut.cull_inside);
  cut = parseMeshCut("/data/left:hemi.obj:outside");
  EXPECT_EQ(cut.spec, "/data/left:hemi.obj") << "a path keeps its colons";
  EXPECT_FALSE(cut.cull_inside);
  EXPECT_EQ(meshCutSpec(cut), "/data/left:hemi.obj:outside");
  EXPECT_EQ(parseMeshCut("sphere:0,0,0,5:outside").spec, "sphere:0,0,0,5");
  for (const std::string spec : {"box:0,0,0,1,1,1", "cut.obj", "cut.obj:both", ":inside", "sphere:0,0,0,-1:inside",
                                 "box:1,2:outside", "cut.obj:Inside"})
    expectOneLineErrorNaming(spec, [&] { parseMeshCut(spec); });
}

// min over the planes of the signed distance of p (mm): >= 0 where kept.
double margin(glm::dvec3 p, const std::vector<ClipPlane>& planes) {
  double m = INFINITY;
  for (const ClipPlane& plane : planes)
    m = std::min(m, glm::dot(p - glm::dvec3(plane.point), glm::dvec3(plane.normal)));
  return m;
}

TEST(Cuts, clipSegmentKeepsExactlyTheSampledKeptPart) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-10, 10);
  std::normal_distribution<float> n(0, 1);
  constexpr int kSamples = 2000;
  int kept_whole = 0, clipped = 0, culled = 0;
  for (int trial = 0; trial < 600; ++trial) {
    std::vector<ClipPlane> planes;
    const int count = 1 + trial % int(kMaxClipPlanes);
    for (int k = 0; k < count; ++k)
      planes.push_back(makeClipPlane({u(rng) / 2, u(rng) / 2, u(rng) / 2}, {n(rng), n(rng), n(rng)}, "random"));
    const glm::vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    const auto range = clipSegment(a, b, planes);
    for (int i = 0; i <= kSamples; ++i) {
      const double t = double(i) / kSamples;
      const double m = margin(glm::dvec3(a) + t * (glm::dvec3(b) - glm::dvec3(a)), planes);
      if (std::fabs(m) < 1e-4) continue;  // on a plane, within rounding
      if (m > 0) {
        ASSERT_TRUE(range.has_value()) << "trial " << trial << ": t " << t << " is kept";
        EXPECT_GE(t, range->first - 1e-6) << "trial " << trial;
        EXPECT_LE(t, range->second + 1e-6) << "trial " << trial;
      } else if (range) {
        EXPECT_TRUE(t < range->first + 1e-6 || t > range->second - 1e-6) << "trial " << trial << ": t " << t;
      }
    }
    if (range) {
      EXPECT_LE(0, range->first);
      EXPECT_LE(range->first, range->second);
      EXPECT_LE(range->second, 1);
      // An end inside the segment lies on a plane.
      for (const float t : {range->first, range->second}) {
        if (t > 0 && t < 1) {
          EXPECT_NEAR(margin(glm::dvec3(a) + double(t) * (glm::dvec3(b) - glm::dvec3(a)), planes), 0, 1e-4);
        }
      }
    }
    (!range ? culled : range->first == 0 && range->second == 1 ? kept_whole : clipped)++;
  }
  EXPECT_GT(kept_whole, 20);
  EXPECT_GT(clipped, 100);
  EXPECT_GT(culled, 100);
}

TEST(Cuts, clipSegmentEdgeCases) {
  const std::vector<ClipPlane> z_up = {parseClipPlane("0,0,0,0,0,1")};
  EXPECT_EQ(clipSegment({0, 0, -1}, {0, 0, 3}, {}), (std::pair{0.0f, 1.0f})) << "no planes";
  EXPECT_EQ(clipSegment({0, 0, -1}, {0, 0, 3}, z_up), (std::pair{0.25f, 1.0f}));
  EXPECT_EQ(clipSegment({0, 0, 3}, {0, 0, -1}, z_up), (std::pair{0.0f, 0.75f}));
  EXPECT_EQ(clipSegment({0, 0, -1}, {0, 0, -3}, z_up), std::nullopt);
  EXPECT_EQ(clipSegment({1, 0, 0}, {5, 2, 0}, z_up), (std::pair{0.0f, 1.0f})) << "in the plane: kept";
  EXPECT_EQ(clipSegment({1, 0, 0}, {1, 0, -2}, z_up), (std::pair{0.0f, 0.0f})) << "one point kept";
  EXPECT_EQ(clipSegment({0, 0, 1}, {0, 0, 1}, z_up), (std::pair{0.0f, 1.0f})) << "a point segment";
  // A slab of two facing planes: what lies between them.
  const std::vector<ClipPlane> slab = {parseClipPlane("0,0,-1,0,0,1"), parseClipPlane("0,0,1,0,0,-1")};
  EXPECT_EQ(clipSegment({0, 0, -3}, {0, 0, 5}, slab), (std::pair{0.25f, 0.5f}));
  const std::vector<ClipPlane> apart = {parseClipPlane("0,0,1,0,0,1"), parseClipPlane("0,0,-1,0,0,-1")};
  EXPECT_EQ(clipSegment({0, 0, -3}, {0, 0, 5}, apart), std::nullopt) << "nothing both keep";
}

}  // namespace
}  // namespace fibscope
