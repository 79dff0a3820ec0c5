// The sparse voxel octree of straight streamtubes (McGraw sections
// 3.1-3.3; issue 16 items 1, 2, 6): the voxel grid chosen for a tube model,
// the memory a build needs, the CPU reference of the voxelisation (the
// signed distance of the union of capsules at voxel centres, narrow band),
// and the octree built bottom-up from the sorted Morton codes of the
// leaves, with every segment that touches a leaf in its decoration list.
//
// The GPU build (svo/gpu/gpu_svo.h) voxelises and sorts on the device and
// hands its sorted leaves to buildSvoTree below, so the two builds give the
// same tree from the same leaves.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "shared/svo.h"
#include "tubes/tube_model.h"

namespace fibscope {

struct SvoGrid {
  glm::vec3 origin{0.0f};  // corner of voxel (0, 0, 0), mm
  float voxel = 1.0f;      // mm
  uint32_t levels = 0;     // side = 2^levels
  // Curved tubes (svo-curved): each segment the tube of radius r around its
  // cubic Hermite centre line (svoCurve) rather than the straight capsule.
  bool curved = false;
  uint32_t side() const { return 1u << levels; }
  float band() const { return shader::kSvoBandScale * voxel; }
  glm::vec3 center(uint32_t x, uint32_t y, uint32_t z) const {
    return origin + (glm::vec3(float(x), float(y), float(z)) + 0.5f) * voxel;
  }
};

// The segment s of `model` as a straight capsule (shared/svo.h).
struct SvoCapsule {
  glm::vec3 a{0.0f}, b{0.0f};
  float radius = 0.0f;
};
SvoCapsule svoCapsule(const TubeModel& model, const shader::TubeSegment& s);

// Signed distance of point p to the capsule (seed eq. 1: distance to the
// segment minus r; a zero-length segment is a sphere), float as the shader.
float capsuleDistance(const SvoCapsule& c, const glm::vec3& p);

// The segment s of `model` as a curved tube (svo-curved): the cubic
// Hermite centre line of the tube model (tubeSegmentPoint: ends p0, p1,
// end derivatives m0, m1 = chord * tangent), radius as the capsule's (the
// mean of the two node radii).
struct SvoCurve {
  glm::vec3 p0{0.0f}, m0{0.0f}, p1{0.0f}, m1{0.0f};
  float radius = 0.0f;
};
SvoCurve svoCurve(const TubeModel& model, const shader::TubeSegment& s);

// Signed distance of p to the curved tube: |p - C(u*)| - r at the nearest
// point u* of the centre line C on [0, 1], found by sampling C at
// kSvoCurveSamples + 1 evenly spaced u and refining the nearest sample by
// kSvoCurveNewtonSteps clamped Newton steps on (C(u) - p) . C'(u) = 0 (the
// smaller of the refined and the sampled distance is kept). Nearest-point
// rather than the seed's domain transform f(Mp): the result is the true
// distance wherever the nearest sample lies in the global minimum's basin
// (segments of the tube model turn by well under 90 degrees), so the field
// is 1-Lipschitz and sphere tracing never steps through a surface, and the
// nearest point gives the normal and the position along the fiber
// directly. `u_out` (may be null): u*. Float, as glsl/svo_curve.glsl.
float curveDistance(const SvoCurve& c, const glm::vec3& p, float* u_out = nullptr);

// A box holding the curved segment: the box of its Bezier control points
// p0, p0 + m0 / 3, p1 - m1 / 3, p1 (the curve lies in their convex hull).
void curveBounds(const SvoCurve& c, glm::vec3& lo, glm::vec3& hi);

// The box of segment s's centre line as the grid takes it: the capsule's
// two ends, or (curved) curveBounds; radius: the tube's.
void svoSegmentBounds(const TubeModel& model, const shader::TubeSegment& s, bool curved, glm::vec3& lo, glm::vec3& hi,
                      float& radius);

// The grid for `model`: the box of every capsule widened by r + 2 band,
// cubic, 2^levels voxels a side. `voxel_mm` > 0 is taken as given; 0
// chooses it from the data: r_min / 2 (two voxels per radius: a tube's
// cross-section spans at least 4 voxels, so the narrow band around
// neighbouring tubes stays apart down to a gap of about one voxel), no finer
// than the median segment length / 2 (finer voxels than the segments add
// leaves without adding detail: each leaf still holds the same capsules),
// no coarser than r_min (a leaf then lists the segments of a few radii
// around it, not of a whole bundle), then coarsened by 1.25x until the box
// fits in 2^kSvoMaxLevels voxels. Throws Error
// when voxel_mm < 0 or not finite, the model has no segment, or a given
// voxel needs more than 2^kSvoMaxLevels voxels a side (naming the side).
// `curved`: the box of the curved segments (curveBounds), and the grid's
// `curved` flag set. `memory_limit_bytes` > 0 with voxel_mm 0 (the
// density criterion, the seed's future work): the voxel is coarsened
// further by 1.25x until estimateSvoMemory (at svoSlabDepth's slabs of
// kSvoDefaultFieldBudget) fits the limit, so a dense whole-brain set gets a
// voxel its device can hold instead of a refusal, or the one-level grid
// where no voxel fits (the build then refuses it); a given voxel is never
// changed (the build refuses it, naming the size it needs).
SvoGrid chooseSvoGrid(const TubeModel& model, float voxel_mm, bool curved = false, uint64_t memory_limit_bytes = 0);

// The dense distance slab of a build at most this large by default
// (SvoGpuBuildOptions::field_budget_bytes), and the slab depth (voxels of
// z) a budget gives on `grid`: at least 1, at most the side.
inline constexpr uint64_t kSvoDefaultFieldBudget = uint64_t(64) << 20;
uint32_t svoSlabDepth(const SvoGrid& grid, uint64_t field_budget_bytes);

// What a build will allocate, estimated before allocating (bytes).
struct SvoMemoryNeed {
  // Narrow-band voxels at most: the smallest of the (leaf, segment)
  // references' bound below (a leaf holds at least one), the voxels of the
  // 8^3-voxel bricks that some segment's band box touches, and the grid.
  // The references' bound, the sum of every capsule's band shell /
  // voxel^3, ignores overlap: in dense bundles the voxels deep inside the
  // union are no leaves, so it is an upper bound there, never short.
  uint64_t leaves = 0;
  uint64_t references = 0;
  uint64_t field = 0;       // the GPU's dense distance slab
  uint64_t sort = 0;        // leaf keys and values, twice (the sort's ping-pong)
  uint64_t nodes = 0;       // tree, about 8/7 of the leaves' blocks
  uint64_t decoration = 0;  // count + indices per leaf
  uint64_t lists = 0;       // the slabs' segment lists (a segment in two slabs, as most are at most)
  // The device tree build's own buffers (gpu_svo_tree.cpp): per leaf its
  // list offset and fill cursor and a level's parent codes (at most one a
  // leaf), and a slot word per node below the root (level l at most
  // min(leaves, 8^l) nodes).
  uint64_t tree = 0;
  uint64_t total() const { return field + sort + nodes + decoration + lists + tree; }
};
// `slab_depth` voxels of z per slab of the dense field.
SvoMemoryNeed estimateSvoMemory(const TubeModel& model, const SvoGrid& grid, uint32_t slab_depth);

// One leaf: its Morton code at the finest level and f at its centre.
struct SvoLeaf {
  uint32_t code = 0;
  float distance = 0.0f;
};

struct SvoTree {
  SvoGrid grid;
  std::vector<shader::SvoNode> nodes;  // node 0: the root
  std::vector<uint32_t> decoration;    // per leaf: count, then segment indices
  size_t leaves = 0;
  size_t leaves_over_4 = 0;          // leaves whose list holds more than 4 segments (the seed's limit)
  size_t max_segments_per_leaf = 0;
  size_t references = 0;             // segment indices in all lists
  // Level of detail (shared/svo.h SvoTracePush::lod_px): per internal node,
  // numbered by its child block ((child index - 1) / 8), the segment that
  // stands in for its subtree: the one with the most references in the
  // subtree's lists (the most surface inside the node, so the likeliest to
  // show in a pixel the node covers; ties: the smaller index). Memory beyond
  // the seed's table 1 (nodes + decoration): 4 bytes per internal node.
  std::vector<uint32_t> lod;
  size_t nodeBytes() const { return nodes.size() * sizeof(nodes[0]); }
  size_t decorationBytes() const { return decoration.size() * sizeof(uint32_t); }
  size_t lodBytes() const { return lod.size() * sizeof(uint32_t); }
};

// Wall time of buildSvoTree's parts: the (leaf, segment) pairs (the
// distance at every voxel of every segment's box), their sort and the
// lists, the node layout, the level of detail.
struct SvoTreeTimes {
  double pairs_s = 0, sort_s = 0, layout_s = 0, lod_s = 0;
};

// CPU reference of the voxelisation: the leaves (|f| < band) in Morton
// order. Cost O(sum of segment box voxels); memory O(grid side^3 / 8)
// at most (a hash of the band voxels).
std::vector<SvoLeaf> voxelizeSvoLeaves(const TubeModel& model, const SvoGrid& grid);

// Straight capsules, or curved tubes where grid.curved (also for the CPU
// reference of the voxelisation above).
// The tree over `leaves` (sorted by code, codes unique) and their lists:
// segment s is in the list of a leaf where |f_s(centre)| < band. Internal
// nodes from the leaves' codes level by level upward (code >> 3 is the
// parent's), laid out top-down: root, then the level-1 block, then each
// level's blocks in code order; `lod` from the same lists. Throws Error
// when the decoration exceeds 2^30 words.
SvoTree buildSvoTree(const TubeModel& model, const SvoGrid& grid, const std::vector<SvoLeaf>& leaves,
                     SvoTreeTimes* times = nullptr);

// SvoTree::lod from the tree itself (its nodes and decoration lists, the
// leaves at level `levels`), as buildSvoTree defines it: the level
// structure read off the node layout (level l + 1's blocks follow level
// l's, one per internal node in order), each internal node's
// most-referenced segment by merging its children's (segment, count) runs
// level by level upward. For the GPU build, whose lists are on the host
// only after their download. Cost O(references * levels * log).
std::vector<uint32_t> svoLodFromTree(const std::vector<shader::SvoNode>& nodes,
                                     const std::vector<uint32_t>& decoration, uint32_t levels);

// One level of the level of detail's upward merge (buildSvoTree,
// svoLodFromTree): `entries` (node rank, segment, references), in runs of
// equal rank in rank order; each run sorted by segment, equal segments
// added up (entries shrinks to the merged ones), and `lod[slot(rank)]` set
// to the run's most referenced segment (ties: the smaller index).
struct SvoLodEntry {
  uint32_t rank, segment, count;
};
template <typename Slot>
void mergeSvoLodLevel(std::vector<SvoLodEntry>& entries, std::vector<uint32_t>& lod, Slot slot);

// tree.leaves_over_4, max_segments_per_leaf and references from its
// decoration (tree.leaves lists, one after the other).
void svoCountListStats(SvoTree& tree);

// voxelizeSvoLeaves then buildSvoTree.
SvoTree buildSvoCpu(const TubeModel& model, const SvoGrid& grid);

// Front intersection of the ray o + t d (|d| = 1), t > t_min, with the
// capsule, in double (cylinder side and the two end spheres; a
// zero-length segment is its sphere). False when it misses.
bool intersectCapsule(const glm::dvec3& a, const glm::dvec3& b, double r, const glm::dvec3& o, const glm::dvec3& d,
                      double t_min, double& t);

template <typename Slot>
void mergeSvoLodLevel(std::vector<SvoLodEntry>& entries, std::vector<uint32_t>& lod, Slot slot) {
  size_t out = 0;
  for (size_t i = 0; i < entries.size();) {
    const uint32_t rank = entries[i].rank;
    size_t end = i;
    while (end < entries.size() && entries[end].rank == rank) ++end;
    std::sort(entries.begin() + ptrdiff_t(i), entries.begin() + ptrdiff_t(end),
              [](const SvoLodEntry& a, const SvoLodEntry& b) { return a.segment < b.segment; });
    uint32_t best = entries[i].segment, best_count = 0;
    for (size_t k = i; k < end;) {
      SvoLodEntry merged = entries[k];
      for (++k; k < end && entries[k].segment == merged.segment; ++k) merged.count += entries[k].count;
      if (merged.count > best_count) {
        best_count = merged.count;
        best = merged.segment;
      }
      entries[out++] = merged;
    }
    lod[slot(rank)] = best;
    i = end;
  }
  entries.resize(out);
}

}  // namespace fibscope
