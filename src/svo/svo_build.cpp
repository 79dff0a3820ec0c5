#include "svo/svo_build.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <unordered_map>
#include <utility>

#include <glm/geometric.hpp>

#include "core/error.h"

namespace fibscope {
namespace {

glm::vec3 nodePosition(const shader::TubeNode& n) {
  return {n.position_radius.x, n.position_radius.y, n.position_radius.z};
}

// The segment as the grid takes it: a capsule or a curved tube.
struct SegmentShape {
  bool curved = false;
  SvoCapsule capsule;
  SvoCurve curve;
  float radius() const { return curved ? curve.radius : capsule.radius; }
  float distance(const glm::vec3& p) const { return curved ? curveDistance(curve, p) : capsuleDistance(capsule, p); }
  void bounds(glm::vec3& lo, glm::vec3& hi) const {
    if (curved) {
      curveBounds(curve, lo, hi);
    } else {
      lo = glm::min(capsule.a, capsule.b);
      hi = glm::max(capsule.a, capsule.b);
    }
  }
};
SegmentShape segmentShape(const TubeModel& model, const shader::TubeSegment& s, bool curved) {
  SegmentShape shape;
  shape.curved = curved;
  if (curved) shape.curve = svoCurve(model, s);
  else shape.capsule = svoCapsule(model, s);
  return shape;
}

// The voxel box [lo, hi] (inclusive, clamped) whose centres lie within
// `pad` of the segment's box.
void voxelBox(const SvoGrid& grid, const SegmentShape& c, float pad, glm::ivec3& lo, glm::ivec3& hi) {
  glm::vec3 bmin, bmax;
  c.bounds(bmin, bmax);
  bmin -= pad;
  bmax += pad;
  const int side = int(grid.side());
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::max(0, int(std::floor((bmin[k] - grid.origin[k]) / grid.voxel - 0.5f)));
    hi[k] = std::min(side - 1, int(std::ceil((bmax[k] - grid.origin[k]) / grid.voxel - 0.5f)));
  }
}

}  // namespace

SvoCapsule svoCapsule(const TubeModel& model, const shader::TubeSegment& s) {
  const shader::TubeNode& na = model.nodes[s.node];
  const shader::TubeNode& nb = model.nodes[s.node + 1];
  return {nodePosition(na), nodePosition(nb), 0.5f * (na.position_radius.w + nb.position_radius.w)};
}

float capsuleDistance(const SvoCapsule& c, const glm::vec3& p) {
  const glm::vec3 ba = c.b - c.a, pa = p - c.a;
  const float baba = glm::dot(ba, ba);
  const float h = baba > 0.0f ? std::clamp(glm::dot(pa, ba) / baba, 0.0f, 1.0f) : 0.0f;
  return glm::length(pa - h * ba) - c.radius;
}

SvoCurve svoCurve(const TubeModel& model, const shader::TubeSegment& s) {
  const shader::TubeNode& na = model.nodes[s.node];
  const shader::TubeNode& nb = model.nodes[s.node + 1];
  SvoCurve c;
  c.p0 = nodePosition(na);
  c.p1 = nodePosition(nb);
  c.m0 = s.chord * glm::vec3(na.tangent_dradius.x, na.tangent_dradius.y, na.tangent_dradius.z);
  c.m1 = s.chord * glm::vec3(nb.tangent_dradius.x, nb.tangent_dradius.y, nb.tangent_dradius.z);
  c.radius = 0.5f * (na.position_radius.w + nb.position_radius.w);
  return c;
}

float curveDistance(const SvoCurve& c, const glm::vec3& p, float* u_out) {
  const uint32_t n = shader::kSvoCurveSamples;
  float best_u = 0.0f, best = INFINITY;
  for (uint32_t k = 0; k <= n; ++k) {
    const float u = float(k) / float(n);
    const glm::vec3 e = hermitePoint(c.p0, c.m0, c.p1, c.m1, u) - p;
    const float d2 = glm::dot(e, e);
    if (d2 < best) {
      best = d2;
      best_u = u;
    }
  }
  float u = best_u;
  for (uint32_t it = 0; it < shader::kSvoCurveNewtonSteps; ++it) {
    const glm::vec3 e = hermitePoint(c.p0, c.m0, c.p1, c.m1, u) - p;
    const glm::vec3 d1 = hermiteDerivative(c.p0, c.m0, c.p1, c.m1, u);
    const glm::vec3 d2 = (12.0f * u - 6.0f) * c.p0 + (6.0f * u - 4.0f) * c.m0 + (6.0f - 12.0f * u) * c.p1 +
                         (6.0f * u - 2.0f) * c.m1;
    const float g = glm::dot(e, d1), h = glm::dot(d1, d1) + glm::dot(e, d2);
    if (!(h > 0.0f)) break;
    u = std::clamp(u - g / h, 0.0f, 1.0f);
  }
  const glm::vec3 e = hermitePoint(c.p0, c.m0, c.p1, c.m1, u) - p;
  float d2 = glm::dot(e, e);
  if (!(d2 <= best)) {
    d2 = best;
    u = best_u;
  }
  if (u_out) *u_out = u;
  return std::sqrt(d2) - c.radius;
}

void curveBounds(const SvoCurve& c, glm::vec3& lo, glm::vec3& hi) {
  const glm::vec3 b1 = c.p0 + c.m0 / 3.0f, b2 = c.p1 - c.m1 / 3.0f;
  lo = glm::min(glm::min(c.p0, c.p1), glm::min(b1, b2));
  hi = glm::max(glm::max(c.p0, c.p1), glm::max(b1, b2));
}

void svoSegmentBounds(const TubeModel& model, const shader::TubeSegment& s, bool curved, glm::vec3& lo, glm::vec3& hi,
                      float& radius) {
  const SegmentShape shape = segmentShape(model, s, curved);
  shape.bounds(lo, hi);
  radius = shape.radius();
}

SvoGrid chooseSvoGrid(const TubeModel& model, float voxel_mm, bool curved, uint64_t memory_limit_bytes) {
  if (!std::isfinite(voxel_mm) || voxel_mm < 0.0f)
    throw Error("svo: the voxel size must be > 0 mm (got " + std::to_string(voxel_mm) + ")");
  if (model.segments.empty()) throw Error("svo: no tube segment to voxelise");
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  float r_min = INFINITY, r_max = 0.0f;
  std::vector<float> lengths;
  lengths.reserve(model.segments.size());
  for (const shader::TubeSegment& s : model.segments) {
    const SegmentShape shape = segmentShape(model, s, curved);
    const float radius = shape.radius();
    glm::vec3 slo, shi;
    shape.bounds(slo, shi);
    lo = glm::min(lo, slo);
    hi = glm::max(hi, shi);
    const SvoCapsule c{slo, shi, radius};
    r_min = std::min(r_min, c.radius);
    r_max = std::max(r_max, c.radius);
    if (s.chord > 0.0f) lengths.push_back(s.chord);
  }
  float voxel = voxel_mm;
  if (voxel == 0.0f) {
    voxel = 0.5f * r_min;
    if (!lengths.empty()) {
      std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
      voxel = std::max(voxel, 0.5f * lengths[lengths.size() / 2]);
      voxel = std::min(voxel, r_min);  // but at least one voxel per radius
    }
  }
  SvoGrid grid;
  grid.curved = curved;
  for (;;) {
    const float pad = r_max + 2.0f * shader::kSvoBandScale * voxel;
    const glm::vec3 extent = hi - lo + 2.0f * pad;
    const float largest = std::max(extent.x, std::max(extent.y, extent.z));
    const double cells = std::ceil(double(largest) / double(voxel));
    uint32_t levels = 0;
    while (levels <= shader::kSvoMaxLevels && double(1u << levels) < cells) ++levels;
    if (levels <= shader::kSvoMaxLevels) {
      grid.voxel = voxel;
      grid.levels = std::max(levels, 1u);
      // Centred on the tubes' box.
      grid.origin = 0.5f * (lo + hi) - 0.5f * float(grid.side()) * voxel;
      // At one level the grid cannot shrink further (coarser voxels would
      // loop for ever where a size-independent part, the segment lists,
      // exceeds the limit): the build then refuses it, naming the size.
      if (voxel_mm > 0.0f || memory_limit_bytes == 0 || grid.levels == 1 ||
          estimateSvoMemory(model, grid, svoSlabDepth(grid, kSvoDefaultFieldBudget)).total() <= memory_limit_bytes)
        return grid;
    }
    if (voxel_mm > 0.0f)
      throw Error("svo: a voxel of " + std::to_string(voxel_mm) + " mm needs " + std::to_string(uint64_t(cells)) +
                  " voxels a side, more than the octree's " + std::to_string(1u << shader::kSvoMaxLevels) +
                  " (choose a voxel of at least " + std::to_string(largest / float(1u << shader::kSvoMaxLevels)) +
                  " mm)");
    voxel *= 1.25f;
  }
}

uint32_t svoSlabDepth(const SvoGrid& grid, uint64_t field_budget_bytes) {
  const uint64_t side = grid.side(), plane_bytes = side * side * 4;
  return uint32_t(std::clamp<uint64_t>(field_budget_bytes / plane_bytes, 1, side));
}

SvoMemoryNeed estimateSvoMemory(const TubeModel& model, const SvoGrid& grid, uint32_t slab_depth) {
  SvoMemoryNeed need;
  const double h = grid.voxel, band = grid.band();
  // Bricks of 8^3 voxels touched by a segment's band box, one bit each
  // (128^3 bits, 256 KB, at the largest grid).
  const uint32_t brick_shift = std::min(grid.levels, 3u);
  const uint64_t bricks_side = uint64_t(grid.side()) >> brick_shift;
  std::vector<uint64_t> touched((bricks_side * bricks_side * bricks_side + 63) / 64, 0);
  double shell = 0.0;
  for (const shader::TubeSegment& s : model.segments) {
    const SvoCapsule c = svoCapsule(model, s);
    const SegmentShape shape{false, c, {}};
    glm::ivec3 vlo, vhi;
    voxelBox(grid, shape, c.radius + float(band), vlo, vhi);
    for (int z = vlo.z >> brick_shift; z <= vhi.z >> brick_shift; ++z)
      for (int y = vlo.y >> brick_shift; y <= vhi.y >> brick_shift; ++y)
        for (int x = vlo.x >> brick_shift; x <= vhi.x >> brick_shift; ++x) {
          const uint64_t i = (uint64_t(z) * bricks_side + uint64_t(y)) * bricks_side + uint64_t(x);
          touched[i >> 6] |= uint64_t(1) << (i & 63);
        }
    const double ro = c.radius + band, ri = std::max(0.0, double(c.radius) - band);
    const double len = glm::length(c.b - c.a);
    // Cylinder shell plus the sphere shell (of the caps, counted once per
    // segment: an upper bound where segments join).
    shell += M_PI * (ro * ro - ri * ri) * len + 4.0 / 3.0 * M_PI * (ro * ro * ro - ri * ri * ri);
  }
  // Each segment's own band voxels: the (leaf, segment) references, and an
  // upper bound of the leaves (a leaf holds at least one reference).
  const uint64_t references = uint64_t(std::ceil(shell / (h * h * h))) + 1;
  uint64_t bricks = 0;
  for (const uint64_t word : touched) bricks += uint64_t(__builtin_popcountll(word));
  const uint64_t side = grid.side();
  need.references = references;
  need.leaves = std::min({references, bricks << (3 * brick_shift), side * side * side});
  need.field = side * side * std::min<uint64_t>(slab_depth, side) * 4;
  need.sort = need.leaves * 4 * 4;
  need.nodes = need.leaves * 8 * 8 / 7 + 8;
  need.decoration = (need.leaves + references) * 4;  // a count per leaf, an index per reference
  need.lists = uint64_t(model.segments.size()) * 2 * 4;
  // Slot words: one per node of levels 1 .. levels, level l holding at
  // most min(leaves, 8^l) nodes (and each level's scan total word).
  uint64_t slot_words = 0;
  for (uint32_t lvl = 1; lvl <= grid.levels; ++lvl)
    slot_words += std::min<uint64_t>(need.leaves, uint64_t(1) << std::min(3 * lvl, 62u)) + 1;
  need.tree = (3 * need.leaves + 1 + slot_words) * 4;
  return need;
}

std::vector<SvoLeaf> voxelizeSvoLeaves(const TubeModel& model, const SvoGrid& grid) {
  const float band = grid.band();
  std::unordered_map<uint32_t, float> field;
  for (const shader::TubeSegment& s : model.segments) {
    const SegmentShape c = segmentShape(model, s, grid.curved);
    glm::ivec3 lo, hi;
    voxelBox(grid, c, c.radius() + band, lo, hi);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const float f = c.distance(grid.center(uint32_t(x), uint32_t(y), uint32_t(z)));
          if (!(f < band)) continue;
          const uint32_t code = shader::svoMorton(uint32_t(x), uint32_t(y), uint32_t(z));
          auto [it, fresh] = field.emplace(code, f);
          if (!fresh) it->second = std::min(it->second, f);
        }
  }
  std::vector<SvoLeaf> leaves;
  for (const auto& [code, f] : field)
    if (std::fabs(f) < band) leaves.push_back({code, f});
  std::sort(leaves.begin(), leaves.end(), [](const SvoLeaf& a, const SvoLeaf& b) { return a.code < b.code; });
  return leaves;
}

SvoTree buildSvoTree(const TubeModel& model, const SvoGrid& grid, const std::vector<SvoLeaf>& leaves,
                     SvoTreeTimes* times) {
  SvoTreeTimes local_times;
  SvoTreeTimes& tt = times ? *times : local_times;
  auto clock = std::chrono::steady_clock::now();
  // Seconds since the last lap.
  auto lap = [&clock]() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - clock).count();
    clock = now;
    return s;
  };
  SvoTree tree;
  tree.grid = grid;
  tree.leaves = leaves.size();
  const uint32_t levels = grid.levels;
  if (leaves.empty()) {
    tree.nodes.push_back({shader::kSvoNodeEmpty, 0.0f});
    return tree;
  }
  // Codes per level, bottom-up: a parent's code is its child's >> 3.
  std::vector<std::vector<uint32_t>> codes(levels + 1);
  codes[levels].reserve(leaves.size());
  for (const SvoLeaf& l : leaves) codes[levels].push_back(l.code);
  for (uint32_t lvl = levels; lvl > 0; --lvl) {
    std::vector<uint32_t>& up = codes[lvl - 1];
    for (const uint32_t c : codes[lvl])
      if (up.empty() || up.back() != (c >> 3)) up.push_back(c >> 3);
  }
  // Layout: node 0 the root; level l's blocks from base[l], one block of 8
  // per node of level l - 1, in code order.
  std::vector<size_t> base(levels + 2, 0);
  base[1] = 1;
  for (uint32_t lvl = 1; lvl <= levels; ++lvl) base[lvl + 1] = base[lvl] + 8 * codes[lvl - 1].size();
  tree.nodes.assign(base[levels + 1], {shader::kSvoNodeEmpty, 0.0f});

  tt.layout_s += lap();  // the levels' codes (the nodes' part of the layout)

  // Decoration lists: the (leaf, segment) pairs, by leaf.
  const float band = grid.band();
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (uint32_t si = 0; si < model.segments.size(); ++si) {
    const SegmentShape c = segmentShape(model, model.segments[si], grid.curved);
    glm::ivec3 lo, hi;
    voxelBox(grid, c, c.radius() + band, lo, hi);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const float f = c.distance(grid.center(uint32_t(x), uint32_t(y), uint32_t(z)));
          if (!(std::fabs(f) < band)) continue;
          const uint32_t code = shader::svoMorton(uint32_t(x), uint32_t(y), uint32_t(z));
          const auto it = std::lower_bound(codes[levels].begin(), codes[levels].end(), code);
          if (it == codes[levels].end() || *it != code) continue;  // inside another tube: not a leaf
          pairs.emplace_back(uint32_t(it - codes[levels].begin()), si);
        }
  }
  tt.pairs_s += lap();
  std::sort(pairs.begin(), pairs.end());
  tree.decoration.reserve(leaves.size() + pairs.size());
  tree.references = pairs.size();
  std::vector<uint32_t> list_offset(leaves.size());
  for (size_t p = 0, leaf = 0; leaf < leaves.size(); ++leaf) {
    list_offset[leaf] = uint32_t(tree.decoration.size());
    const size_t count_at = tree.decoration.size();
    tree.decoration.push_back(0);
    size_t n = 0;
    for (; p < pairs.size() && pairs[p].first == leaf; ++p, ++n) tree.decoration.push_back(pairs[p].second);
    tree.decoration[count_at] = uint32_t(n);
    tree.leaves_over_4 += n > 4;
    tree.max_segments_per_leaf = std::max(tree.max_segments_per_leaf, n);
  }
  if (tree.decoration.size() > shader::kSvoNodeIndexMask)
    throw Error("svo: the decoration holds " + std::to_string(tree.decoration.size()) +
                " words, more than the 2^30 a leaf reference reaches");
  tt.sort_s += lap();

  // Every node of level l (rank j among them) sits at slot (code & 7) of
  // its parent's block (the parent's rank p among level l - 1).
  for (uint32_t lvl = 0; lvl <= levels; ++lvl) {
    const std::vector<uint32_t>& here = codes[lvl];
    for (size_t j = 0, p = 0; j < here.size(); ++j) {
      size_t index = 0;
      if (lvl > 0) {
        const std::vector<uint32_t>& up = codes[lvl - 1];
        while (up[p] != (here[j] >> 3)) ++p;
        index = base[lvl] + 8 * p + (here[j] & 7u);
      }
      if (lvl < levels)
        tree.nodes[index] = {shader::kSvoNodeInternal | uint32_t(base[lvl + 1] + 8 * j), 0.0f};
      else
        tree.nodes[index] = {shader::kSvoNodeLeaf | list_offset[j], leaves[j].distance};
    }
  }
  tt.layout_s += lap();

  // Level of detail: the (node rank, segment, references) of each level,
  // from the leaves' (leaf, segment) pairs merged upward level by level
  // (a rank maps to its parent's, then equal pairs add up); each internal
  // node's representative is its most referenced segment. Cost
  // O(references * levels * log); the lists shrink upward as children
  // share segments.
  std::vector<SvoLodEntry> entries;
  entries.reserve(pairs.size());
  for (const auto& [leaf, segment] : pairs) entries.push_back({leaf, segment, 1});
  tree.lod.assign((tree.nodes.size() - 1) / 8, 0);
  std::vector<uint32_t> parent;
  for (uint32_t lvl = levels; lvl > 0; --lvl) {
    const std::vector<uint32_t>& here = codes[lvl];
    const std::vector<uint32_t>& up = codes[lvl - 1];
    parent.resize(here.size());
    for (size_t j = 0, p = 0; j < here.size(); ++j) {
      while (up[p] != (here[j] >> 3)) ++p;
      parent[j] = uint32_t(p);
    }
    for (SvoLodEntry& e : entries) e.rank = parent[e.rank];
    // Ranks stay in order (the parent's rank grows with the child's); sort
    // each parent's run by segment and add up equal segments. A node whose
    // lists are all empty (a leaf at the band's float edge) keeps segment 0.
    // Node `rank` of level lvl - 1 owns the block at base[lvl] + 8 rank.
    mergeSvoLodLevel(entries, tree.lod, [&](uint32_t rank) { return (base[lvl] + 8 * size_t(rank) - 1) / 8; });
  }
  tt.lod_s += lap();
  return tree;
}

SvoTree buildSvoCpu(const TubeModel& model, const SvoGrid& grid) {
  return buildSvoTree(model, grid, voxelizeSvoLeaves(model, grid));
}

bool intersectCapsule(const glm::dvec3& a, const glm::dvec3& b, double r, const glm::dvec3& o, const glm::dvec3& d,
                      double t_min, double& t) {
  bool hit = false;
  double best = INFINITY;
  auto consider = [&](double s) {
    if (s > t_min && s < best) {
      best = s;
      hit = true;
    }
  };
  // The end spheres (stable form: h is the ray's offset from the centre).
  for (const glm::dvec3& c : {a, b}) {
    const double bq = glm::dot(c - o, d);
    const glm::dvec3 h = (c - o) - bq * d;
    const double disc = r * r - glm::dot(h, h);
    if (disc >= 0.0) consider(bq - std::sqrt(disc));
  }
  const glm::dvec3 ba = b - a;
  const double len = glm::length(ba);
  if (len > 0.0) {
    const glm::dvec3 u = ba / len;
    // Origin moved along the ray to its closest approach to a, for precision.
    const double tc = glm::dot(a - o, d);
    const glm::dvec3 oa = o + tc * d - a;
    const glm::dvec3 op = oa - glm::dot(oa, u) * u, dp = d - glm::dot(d, u) * u;
    const double A = glm::dot(dp, dp), B = glm::dot(op, dp), C = glm::dot(op, op) - r * r;
    const double disc = B * B - A * C;
    if (A > 0.0 && disc >= 0.0) {
      const double s = (-B - std::sqrt(disc)) / A;
      const double y = glm::dot(oa, u) + s * glm::dot(d, u);
      if (y >= 0.0 && y <= len) consider(tc + s);
    }
  }
  t = best;
  return hit;
}

}  // namespace fibscope
