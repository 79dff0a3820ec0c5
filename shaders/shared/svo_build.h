// The octree's tree and decoration lists built on the device (issue 16
// item 2; src/svo/gpu/gpu_svo_tree.cpp), from the sorted leaf codes the
// voxelisation and the radix sort leave there, to the layout and values
// of the CPU reference (src/svo/svo_build.h buildSvoTree):
//
//   svo_lists.comp      per segment: the leaves its band reaches; phase 0
//                       counts them per leaf, phase 1 writes the segment
//                       into the leaf's list (after the scan of count + 1
//                       gave each list's word offset)
//   svo_list_sort.comp  per leaf: its count word, its list sorted by index
//   svo_levels.comp     per node of a level: phase 0 flags the first child
//                       of each parent, phase 1 (after the scan of the
//                       flags: parent ranks) writes the parent codes and
//                       each node's slot 8 * parent rank + (code & 7)
//   svo_nodes.comp      per node of a level: its SvoNode at base + slot
//
// Baert, Lagae, Dutre, "Out-of-core construction of sparse voxel octrees"
// (bottom-up from sorted Morton codes), on the device.
#ifndef FIBSCOPE_SHADERS_SHARED_SVO_BUILD_H
#define FIBSCOPE_SHADERS_SHARED_SVO_BUILD_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define SVO_BUILD_CONST inline constexpr
#else
#define SVO_BUILD_CONST const
#endif

SHADER_NAMESPACE_BEGIN

SVO_BUILD_CONST uint kSvoListsGroupSize = 64u;    // svo_lists.comp: one workgroup per segment
SVO_BUILD_CONST uint kSvoTreeGroupSize = 256u;    // the other three: one invocation per leaf or node

// svo_lists.comp: workgroup g takes segment segment_first + g; its
// invocations walk the voxels of the segment's box widened by r + band
// (voxelBox of svo_build.cpp) and, where |f_s(centre)| < band (the
// curved distance where curved), binary-search the voxel's code among the
// leaf codes (specialisation constant 0: curved tubes, glsl/svo_curve.glsl,
// else capsules). Phase 0: atomicAdd(offsets[leaf], 1). Phase 1:
// slot = atomicAdd(cursor[leaf], 1), and the segment index to
// decoration[offsets[leaf] + 1 + slot] (slot below the list's length
// offsets[leaf + 1] - offsets[leaf] - 1 only). One shader for both phases
// (a push constant, not a specialisation) so both evaluate the same
// compiled distance and find the same leaves.
struct SvoListsPush {
  uint64_t nodes;       // TubeNode[]
  uint64_t segments;    // TubeSegment[]
  uint64_t codes;       // uint[leaf_count], sorted, unique
  uint64_t offsets;     // uint[leaf_count + 1]
  uint64_t cursor;      // uint[leaf_count], 0 before phase 1
  uint64_t decoration;  // uint[offsets[leaf_count]] (phase 1)
  float origin_x, origin_y, origin_z;  // grid origin (mm)
  float voxel;                         // mm
  uint side;
  uint leaf_count;
  uint segment_first;
  uint segment_count;
  float band;
  uint phase;  // 0: count, 1: fill
  uint pad0;
  uint pad1;
};

// svo_list_sort.comp: invocation i < leaf_count: n = offsets[i + 1] -
// offsets[i] - 1; decoration[offsets[i]] = n and the n indices after it
// sorted ascending (in place: a shell sort, lists of a few to hundreds of
// words).
struct SvoListSortPush {
  uint64_t offsets;     // uint[leaf_count + 1], scanned
  uint64_t decoration;  // uint[]
  uint leaf_count;
  uint pad0;
  uint pad1;
  uint pad2;
};

// svo_levels.comp over the count codes of one level (sorted, unique):
// phase 0: ranks[i] = 1 where i == 0 or codes[i] >> 3 != codes[i - 1] >>
// 3 (i starts a parent), else 0; ranks[count] = 0. Phase 1, after the
// exclusive scan of ranks[0 .. count] (ranks[count] then the parents'
// count): where i starts a parent, parents[ranks[i]] = codes[i] >> 3;
// ranks[i] = 8 * (its parent's rank) + (codes[i] & 7), its slot in the
// parent level's blocks.
struct SvoLevelPush {
  uint64_t codes;    // uint[count]
  uint64_t ranks;    // uint[count + 1]
  uint64_t parents;  // uint[parents' count] (phase 1)
  uint count;
  uint phase;  // 0: flags, 1: parents and slots
};

// svo_nodes.comp over the count nodes of one level (rank j): the node at
// base + slots[j] (slots 0: the root, node 0): internal (leaf == 0):
// kSvoNodeInternal | (child_base + 8 j), distance 0; leaf:
// kSvoNodeLeaf | offsets[j], distance uintBitsToFloat(distances[j]).
struct SvoNodesPush {
  uint64_t nodes;      // SvoNode[], kSvoNodeEmpty (zero) before
  uint64_t slots;      // uint[count] (0: the root level)
  uint64_t offsets;    // uint[count]: the leaves' list offsets (leaf level)
  uint64_t distances;  // uint[count]: the leaves' f bits (leaf level)
  uint count;
  uint base;        // node index of the level's first block
  uint child_base;  // node index of the level below's first block (internal levels)
  uint leaf;        // 1: the leaf level
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::SvoListsPush) == 96, "");
static_assert(offsetof(fibscope::shader::SvoListsPush, origin_x) == 48, "");
static_assert(offsetof(fibscope::shader::SvoListsPush, phase) == 84, "");
static_assert(sizeof(fibscope::shader::SvoListSortPush) == 32, "");
static_assert(sizeof(fibscope::shader::SvoLevelPush) == 32, "");
static_assert(sizeof(fibscope::shader::SvoNodesPush) == 48, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_SVO_BUILD_H
