// The SVO streamtubes' CPU side (src/svo): Morton codes and ordered keys,
// the grid rule, the tree's layout (every leaf reachable by its code, its
// distance and list), the lists' completeness beyond the seed's 4, and the
// exact ray-capsule intersection.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include <glm/geometric.hpp>

#include "core/error.h"
#include "shared/svo.h"
#include "svo/svo_build.h"
#include "svo_test_scenes.h"

namespace fibscope {
namespace {

TEST(SvoCodes, mortonInterleavesXLowest) {
  EXPECT_EQ(shader::svoMorton(1, 0, 0), 1u);
  EXPECT_EQ(shader::svoMorton(0, 1, 0), 2u);
  EXPECT_EQ(shader::svoMorton(0, 0, 1), 4u);
  EXPECT_EQ(shader::svoMorton(3, 0, 0), 9u);
  EXPECT_EQ(shader::svoMorton(1023, 1023, 1023), (1u << 30) - 1);
}

TEST(SvoCodes, orderedKeysSortAsTheFloats) {
  const float v[] = {-1e30f, -2.5f, -1e-20f, -0.0f, 0.0f, 1e-20f, 0.5f, 3.0f, 1e30f};
  for (size_t i = 0; i + 1 < std::size(v); ++i) {
    EXPECT_LE(shader::svoOrderedKey(v[i]), shader::svoOrderedKey(v[i + 1])) << v[i];
    EXPECT_EQ(shader::svoKeyFloat(shader::svoOrderedKey(v[i])), v[i]);
  }
  EXPECT_LT(shader::svoOrderedKey(1e30f), shader::kSvoFar);
}

TEST(SvoGridRule, voxelIsHalfTheRadiusAndRejectsBadSizes) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  // r / 2 = 0.15 against half the median 1 mm step = 0.5, capped at r.
  EXPECT_FLOAT_EQ(grid.voxel, 0.3f);
  EXPECT_FLOAT_EQ(chooseSvoGrid(model, 0.1f).voxel, 0.1f);
  EXPECT_THROW(chooseSvoGrid(model, -1.0f), Error);
  EXPECT_THROW(chooseSvoGrid(model, NAN), Error);
  try {
    chooseSvoGrid(model, 1e-4f);
    FAIL() << "a voxel far too fine was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("voxels a side"), std::string::npos) << e.what();
  }
}

// The estimate a build checks before allocating is an upper bound of what
// the build makes (leaves, references, node and decoration bytes), and the
// brick bound makes the leaves' part tight enough to matter: on a dense
// bundle it is below the references' (shell) bound, which ignores overlap.
TEST(SvoMemoryEstimate, boundsTheBuildAndTheDensityCriterionFitsTheLimit) {
  // 150 fibers of radius 0.3 mm within a 2.7 mm radius: the tubes overlap.
  const TubeModel model = buildTubes(test::denseSvoBundle(150), test::svoTubeOptions(0.3f));
  for (const float voxel : {0.0f, 0.1f}) {
    const SvoGrid grid = chooseSvoGrid(model, voxel);
    const SvoMemoryNeed need = estimateSvoMemory(model, grid, svoSlabDepth(grid, kSvoDefaultFieldBudget));
    const SvoTree tree = buildSvoCpu(model, grid);
    SCOPED_TRACE(grid.voxel);
    EXPECT_GE(need.leaves, tree.leaves);
    EXPECT_GE(need.references, tree.references);
    EXPECT_GE(need.nodes, tree.nodeBytes());
    EXPECT_GE(need.decoration, tree.decorationBytes());
    // The device tree build's own buffers: offsets, cursors and a level's
    // parent codes per leaf, a slot word per node below the root.
    size_t below_root = 0;
    for (size_t i = 1; i < tree.nodes.size(); ++i) below_root += tree.nodes[i].ref != shader::kSvoNodeEmpty;
    EXPECT_GE(need.tree, (3 * tree.leaves + 1 + below_root + grid.levels) * 4);
    EXPECT_LT(need.leaves, need.references);
  }
  // A limit below the rule's voxel's need: the chosen voxel is coarser, by
  // steps of 1.25x, and its estimate fits; a given voxel is kept.
  const SvoGrid fine = chooseSvoGrid(model, 0.0f);
  const uint64_t fine_need = estimateSvoMemory(model, fine, svoSlabDepth(fine, kSvoDefaultFieldBudget)).total();
  const SvoGrid fitted = chooseSvoGrid(model, 0.0f, false, fine_need / 4);
  EXPECT_GT(fitted.voxel, fine.voxel * 1.2f);
  EXPECT_LE(estimateSvoMemory(model, fitted, svoSlabDepth(fitted, kSvoDefaultFieldBudget)).total(), fine_need / 4);
  const SvoGrid finer = chooseSvoGrid(model, fitted.voxel / 1.25f);
  EXPECT_GT(estimateSvoMemory(model, finer, svoSlabDepth(finer, kSvoDefaultFieldBudget)).total(), fine_need / 4)
      << "the voxel one step finer would have fitted";
  EXPECT_FLOAT_EQ(chooseSvoGrid(model, 0.1f, false, fine_need / 4).voxel, 0.1f);
  EXPECT_FLOAT_EQ(chooseSvoGrid(model, 0.0f, false, fine_need).voxel, fine.voxel);
  // A limit nothing fits (below the segment lists alone): the one-level
  // grid, returned (the build refuses it), not an endless coarsening.
  const SvoGrid none = chooseSvoGrid(model, 0.0f, false, 1);
  EXPECT_EQ(none.levels, 1u);
  EXPECT_GT(estimateSvoMemory(model, none, svoSlabDepth(none, kSvoDefaultFieldBudget)).total(), 1u);
}

// Descends from the root by the code's octants.
const shader::SvoNode* findLeaf(const SvoTree& tree, uint32_t code) {
  uint32_t node = 0;
  for (uint32_t lvl = 0; lvl < tree.grid.levels; ++lvl) {
    const uint32_t ref = tree.nodes[node].ref;
    if ((ref & shader::kSvoNodeTypeMask) != shader::kSvoNodeInternal) return nullptr;
    node = (ref & shader::kSvoNodeIndexMask) + ((code >> (3 * (tree.grid.levels - 1 - lvl))) & 7u);
  }
  return &tree.nodes[node];
}

TEST(SvoTreeBuild, everyLeafIsReachableWithItsDistanceAndEverySegmentThatTouchesIt) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  const std::vector<SvoLeaf> leaves = voxelizeSvoLeaves(model, grid);
  const SvoTree tree = buildSvoTree(model, grid, leaves);
  ASSERT_GT(leaves.size(), 100u);
  EXPECT_EQ(tree.leaves, leaves.size());
  // The dense bundle: many leaves hold more than the seed's 4 segments.
  EXPECT_GT(tree.leaves_over_4, 10u);
  EXPECT_GT(tree.max_segments_per_leaf, 8u);
  size_t leaf_nodes = 0;
  for (const shader::SvoNode& n : tree.nodes) leaf_nodes += (n.ref & shader::kSvoNodeTypeMask) == shader::kSvoNodeLeaf;
  EXPECT_EQ(leaf_nodes, leaves.size());
  const float band = grid.band();
  const uint32_t side = grid.side();
  for (const SvoLeaf& l : leaves) {
    const shader::SvoNode* n = findLeaf(tree, l.code);
    ASSERT_NE(n, nullptr);
    ASSERT_EQ(n->ref & shader::kSvoNodeTypeMask, shader::kSvoNodeLeaf);
    EXPECT_EQ(n->distance, l.distance);
    EXPECT_LT(std::fabs(l.distance), band);
    // The voxel's coordinates from its code, then the list against every segment.
    uint32_t x = 0, y = 0, z = 0;
    for (uint32_t b = 0; b < 10; ++b) {
      x |= ((l.code >> (3 * b)) & 1u) << b;
      y |= ((l.code >> (3 * b + 1)) & 1u) << b;
      z |= ((l.code >> (3 * b + 2)) & 1u) << b;
    }
    ASSERT_LT(std::max(x, std::max(y, z)), side);
    const uint32_t list = n->ref & shader::kSvoNodeIndexMask;
    std::set<uint32_t> listed(tree.decoration.begin() + list + 1,
                              tree.decoration.begin() + list + 1 + tree.decoration[list]);
    float nearest = INFINITY;
    for (uint32_t s = 0; s < model.segments.size(); ++s) {
      const float f = capsuleDistance(svoCapsule(model, model.segments[s]), grid.center(x, y, z));
      nearest = std::min(nearest, f);
      EXPECT_EQ(listed.count(s) == 1, std::fabs(f) < band) << "leaf " << l.code << " segment " << s;
    }
    EXPECT_EQ(nearest, l.distance);  // the union is the min of the capsules
  }
}

// Every reference in the lists of the leaves below `node`, counted by segment.
void countReferences(const SvoTree& tree, uint32_t node, std::map<uint32_t, size_t>& counts) {
  const uint32_t ref = tree.nodes[node].ref, type = ref & shader::kSvoNodeTypeMask;
  const uint32_t index = ref & shader::kSvoNodeIndexMask;
  if (type == shader::kSvoNodeLeaf) {
    for (uint32_t k = 0; k < tree.decoration[index]; ++k) ++counts[tree.decoration[index + 1 + k]];
  } else if (type == shader::kSvoNodeInternal) {
    for (uint32_t c = 0; c < 8; ++c) countReferences(tree, index + c, counts);
  }
}

// The level of detail's representatives (SvoTree::lod), against a count by
// descent: each internal node's is the most referenced segment below it,
// the smaller index on a tie; one word per internal node, at its child
// block's number.
TEST(SvoTreeBuild, lodRepresentativeIsTheMostReferencedSegmentBelowEachInternalNode) {
  for (const bool curved : {false, true}) {
    const TubeModel model = buildTubes(curved ? test::curvedSvoBundle() : test::denseSvoBundle(),
                                       test::svoTubeOptions(0.3f));
    const SvoTree tree = buildSvoCpu(model, chooseSvoGrid(model, 0.0f, curved));
    size_t internal = 0, ties = 0;
    std::set<uint32_t> representatives;
    for (uint32_t node = 0; node < tree.nodes.size(); ++node) {
      const uint32_t ref = tree.nodes[node].ref;
      if ((ref & shader::kSvoNodeTypeMask) != shader::kSvoNodeInternal) continue;
      ++internal;
      const uint32_t block = ((ref & shader::kSvoNodeIndexMask) - 1) / 8;
      ASSERT_LT(block, tree.lod.size());
      std::map<uint32_t, size_t> counts;
      countReferences(tree, node, counts);
      ASSERT_FALSE(counts.empty()) << node;
      uint32_t want = 0;
      size_t most = 0;
      for (const auto& [segment, n] : counts)  // ascending segments: the first of the largest count
        if (n > most) {
          most = n;
          want = segment;
        }
      for (const auto& [segment, n] : counts) ties += n == most && segment != want;
      EXPECT_EQ(tree.lod[block], want) << "node " << node;
      representatives.insert(tree.lod[block]);
    }
    EXPECT_EQ(tree.lod.size(), internal);
    EXPECT_EQ(tree.lodBytes(), 4 * internal);
    EXPECT_GT(internal, 50u);
    EXPECT_GT(ties, 0u);  // the tie rule was exercised
    EXPECT_GT(representatives.size(), 10u);
  }
}

TEST(SvoTreeBuild, noTubesGiveAnEmptyRoot) {
  TubeModel model;
  SvoGrid grid;
  grid.levels = 3;
  const SvoTree tree = buildSvoTree(model, grid, {});
  ASSERT_EQ(tree.nodes.size(), 1u);
  EXPECT_EQ(tree.nodes[0].ref, shader::kSvoNodeEmpty);
  EXPECT_TRUE(tree.lod.empty());
}

TEST(SvoCapsule, intersectionMatchesSpheresAndCylinder) {
  const glm::dvec3 o(0, 0, 10), d(0, 0, -1);
  double t = 0;
  // Zero-length: a sphere of radius 1 at the origin.
  ASSERT_TRUE(intersectCapsule({0, 0, 0}, {0, 0, 0}, 1.0, o, d, 0.0, t));
  EXPECT_NEAR(t, 9.0, 1e-12);
  // A cylinder along x seen from above, off-centre by 0.6.
  ASSERT_TRUE(intersectCapsule({-5, 0.6, 0}, {5, 0.6, 0}, 1.0, o, d, 0.0, t));
  EXPECT_NEAR(t, 10.0 - std::sqrt(1.0 - 0.36), 1e-12);
  // Past the end of the cylinder: the end cap's sphere.
  ASSERT_TRUE(intersectCapsule({-5, 0, 0}, {-0.5, 0, 0}, 1.0, o, d, 0.0, t));
  EXPECT_NEAR(t, 10.0 - std::sqrt(1.0 - 0.25), 1e-12);
  EXPECT_FALSE(intersectCapsule({-5, 2, 0}, {5, 2, 0}, 1.0, o, d, 0.0, t));
  // Behind the origin: no hit.
  EXPECT_FALSE(intersectCapsule({-5, 0, 20}, {5, 0, 20}, 1.0, o, d, 0.0, t));
}

// The curved tube's distance (nearest point by samples and Newton) against
// a dense scan of its centre line (20,000 points: spacing under 1e-4 of the
// segment, so the scan is within ~1e-5 mm of the true distance), at random
// points around every segment of the curved scene; and the segment's
// centre line inside the box of its Bezier control points.
TEST(SvoCurve, distanceIsTheNearestPointOfTheHermiteCurve) {
  const TubeModel model = buildTubes(test::curvedSvoBundle(), test::svoTubeOptions(0.3f));
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-1.5f, 1.5f);
  double worst = 0;
  for (const shader::TubeSegment& s : model.segments) {
    const SvoCurve c = svoCurve(model, s);
    glm::vec3 lo, hi;
    curveBounds(c, lo, hi);
    std::vector<glm::vec3> scan;
    for (int k = 0; k <= 20000; ++k) {
      const glm::vec3 q = tubeSegmentPoint(model, s, float(k) / 20000.0f);
      EXPECT_TRUE(glm::all(glm::greaterThanEqual(q, lo - 1e-4f)) && glm::all(glm::lessThanEqual(q, hi + 1e-4f)));
      scan.push_back(q);
    }
    for (int n = 0; n < 8; ++n) {
      const glm::vec3 p = 0.5f * (lo + hi) + glm::vec3(jitter(rng), jitter(rng), jitter(rng));
      double want = INFINITY;
      for (const glm::vec3& q : scan) want = std::min(want, double(glm::length(p - q)));
      float u = -1.0f;
      const double got = double(curveDistance(c, p, &u)) + double(c.radius);
      worst = std::max(worst, std::fabs(got - want));
      EXPECT_GE(u, 0.0f);
      EXPECT_LE(u, 1.0f);
      EXPECT_NEAR(got, double(glm::length(p - tubeSegmentPoint(model, s, u))), 1e-4);
    }
  }
  std::printf("curved distance: worst error %.2e mm against a dense scan\n", worst);
  EXPECT_LE(worst, 1e-4);
}

// A curved grid's tree: every curved segment is listed in every leaf where
// its own distance is within the band (so the sphere tracing of a leaf
// sees every surface that crosses it), and the lists differ from the
// straight capsules' (the tubes really bow).
TEST(SvoCurve, curvedTreeListsEverySegmentWithinTheBandOfTheCurve) {
  const TubeModel model = buildTubes(test::curvedSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f, true);
  EXPECT_TRUE(grid.curved);
  const SvoTree tree = buildSvoCpu(model, grid);
  SvoGrid straight_grid = grid;
  straight_grid.curved = false;
  const SvoTree straight = buildSvoCpu(model, straight_grid);
  EXPECT_GT(tree.leaves, 100u);
  EXPECT_NE(tree.leaves, straight.leaves);
  // Walk each leaf by its code and check its list against a brute force.
  const std::vector<SvoLeaf> leaves = voxelizeSvoLeaves(model, grid);
  ASSERT_EQ(leaves.size(), tree.leaves);
  for (size_t li = 0; li < leaves.size(); li += 7) {
    const uint32_t code = leaves[li].code;
    uint32_t node = 0;
    for (uint32_t lvl = 0; lvl < grid.levels; ++lvl) {
      const uint32_t ref = tree.nodes[node].ref;
      ASSERT_EQ(ref & shader::kSvoNodeTypeMask, shader::kSvoNodeInternal);
      node = (ref & shader::kSvoNodeIndexMask) + ((code >> (3 * (grid.levels - 1 - lvl))) & 7u);
    }
    const uint32_t ref = tree.nodes[node].ref;
    ASSERT_EQ(ref & shader::kSvoNodeTypeMask, shader::kSvoNodeLeaf);
    const uint32_t at = ref & shader::kSvoNodeIndexMask;
    const std::set<uint32_t> got(tree.decoration.begin() + at + 1,
                                 tree.decoration.begin() + at + 1 + tree.decoration[at]);
    uint32_t x = 0, y = 0, z = 0;
    for (uint32_t b = 0; b < grid.levels; ++b) {
      x |= ((code >> (3 * b)) & 1u) << b;
      y |= ((code >> (3 * b + 1)) & 1u) << b;
      z |= ((code >> (3 * b + 2)) & 1u) << b;
    }
    std::set<uint32_t> want;
    for (uint32_t si = 0; si < model.segments.size(); ++si)
      if (std::fabs(curveDistance(svoCurve(model, model.segments[si]), grid.center(x, y, z))) < grid.band())
        want.insert(si);
    EXPECT_EQ(got, want) << "leaf " << li;
  }
}

}  // namespace
}  // namespace fibscope
