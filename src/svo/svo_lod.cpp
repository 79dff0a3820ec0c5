// The octree's level of detail read off a finished tree (svo_build.h
// svoLodFromTree) and its lists' statistics: for the GPU build, which
// downloads the nodes and lists but not the per-level codes buildSvoTree
// keeps.
#include <algorithm>
#include <string>

#include "core/error.h"
#include "svo/svo_build.h"

namespace fibscope {
namespace {

bool isType(const shader::SvoNode& n, uint32_t type) { return (n.ref & shader::kSvoNodeTypeMask) == type; }

}  // namespace

std::vector<uint32_t> svoLodFromTree(const std::vector<shader::SvoNode>& nodes,
                                     const std::vector<uint32_t>& decoration, uint32_t levels) {
  if (nodes.size() <= 1) return {};
  // begin[l]: the first node of level l; level l + 1's blocks follow level
  // l's nodes, one block per internal node of level l, in order.
  std::vector<size_t> begin(levels + 2, 0);
  begin[1] = 1;
  for (uint32_t lvl = 0; lvl < levels; ++lvl) {
    size_t internal = 0;
    for (size_t i = begin[lvl]; i < begin[lvl + 1]; ++i) internal += isType(nodes[i], shader::kSvoNodeInternal);
    begin[lvl + 2] = begin[lvl + 1] + 8 * internal;
  }
  if (begin[levels + 1] != nodes.size())
    throw Error("svo: the tree's levels hold " + std::to_string(begin[levels + 1]) + " nodes, not its " +
                std::to_string(nodes.size()));
  std::vector<SvoLodEntry> entries;  // rank: of the parent among its level's internal nodes
  for (size_t i = begin[levels]; i < begin[levels + 1]; ++i) {
    if (!isType(nodes[i], shader::kSvoNodeLeaf)) continue;
    const uint32_t at = nodes[i].ref & shader::kSvoNodeIndexMask;
    const uint32_t rank = uint32_t((i - begin[levels]) / 8);
    for (uint32_t k = 0; k < decoration[at]; ++k) entries.push_back({rank, decoration[at + 1 + k], 1});
  }
  std::vector<uint32_t> lod((nodes.size() - 1) / 8, 0);
  std::vector<uint32_t> parent;
  for (uint32_t lvl = levels; lvl > 0; --lvl) {
    // Entries: the (segment, count) of level lvl's nodes, by their parent's
    // rank among level lvl - 1's internal nodes (in order). Each parent's
    // run sorted by segment, equal segments added up, the most referenced
    // kept (ties: the smaller index, the first in the run).
    // Internal node `rank` of level lvl - 1 owns the block at begin[lvl] + 8 rank.
    mergeSvoLodLevel(entries, lod, [&](uint32_t rank) { return (begin[lvl] + 8 * size_t(rank) - 1) / 8; });
    if (lvl == 1) break;
    // Internal node p of level lvl - 1 (the p-th in order) sits in block
    // (slot - begin[lvl - 1]) / 8 of its level: its parent's rank.
    parent.clear();
    for (size_t i = begin[lvl - 1]; i < begin[lvl]; ++i)
      if (isType(nodes[i], shader::kSvoNodeInternal)) parent.push_back(uint32_t((i - begin[lvl - 1]) / 8));
    for (SvoLodEntry& e : entries) e.rank = parent[e.rank];
  }
  return lod;
}

void svoCountListStats(SvoTree& tree) {
  tree.leaves_over_4 = 0;
  tree.max_segments_per_leaf = 0;
  tree.references = 0;
  size_t at = 0;
  for (size_t leaf = 0; leaf < tree.leaves && at < tree.decoration.size(); ++leaf) {
    const size_t n = tree.decoration[at];
    tree.leaves_over_4 += n > 4;
    tree.max_segments_per_leaf = std::max(tree.max_segments_per_leaf, n);
    tree.references += n;
    at += 1 + n;
  }
}

}  // namespace fibscope
