// The octree's tree and decoration lists built on the device (issue 16
// item 2; src/svo/gpu/gpu_svo_tree.cpp) against the CPU reference
// buildSvoTree on the same GPU leaves: node for node (the same layout,
// references and leaf distances), list for list (a list may differ only
// by a segment whose |f| lies within float rounding of the band at that
// voxel: the two sides evaluate the distance each in its own float code,
// and such segments are counted and bounded), the lists' statistics and
// the level of detail; straight and curved tubes, a scene past 2^16 leaves
// (the scans' chunks) and the build's own path (the leaves left on the
// device). Validation layers on.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu_test_context.h"
#include "io/reader.h"
#include "shared/svo.h"
#include "svo/gpu/gpu_svo.h"
#include "svo/svo_build.h"
#include "svo_test_scenes.h"

namespace fibscope {
namespace {

class GpuSvoTree : public test::GpuTest {};

// The word offsets of a decoration's lists, one after the other.
std::vector<uint32_t> listStarts(const std::vector<uint32_t>& decoration) {
  std::vector<uint32_t> starts;
  for (size_t at = 0; at < decoration.size(); at += 1 + decoration[at]) starts.push_back(uint32_t(at));
  return starts;
}

// The voxel of a Morton code at `levels` bits a coordinate.
void mortonVoxel(uint32_t code, uint32_t levels, uint32_t& x, uint32_t& y, uint32_t& z) {
  x = y = z = 0;
  for (uint32_t b = 0; b < levels; ++b) {
    x |= ((code >> (3 * b)) & 1u) << b;
    y |= ((code >> (3 * b + 1)) & 1u) << b;
    z |= ((code >> (3 * b + 2)) & 1u) << b;
  }
}

float segmentDistance(const TubeModel& model, const SvoGrid& grid, uint32_t segment, const glm::vec3& p) {
  const shader::TubeSegment& s = model.segments[segment];
  return grid.curved ? curveDistance(svoCurve(model, s), p) : capsuleDistance(svoCapsule(model, s), p);
}

struct TreeDifference {
  size_t edge_segments = 0;  // segments in one list only, |f| within rounding of the band
};

// `gpu` against `cpu` (both from `leaves`): nodes alike (a leaf's list by
// its rank among the lists, so that a list one segment longer does not
// shift every later comparison), each list equal but for band-edge
// segments, the statistics and (where the lists are equal) the lod.
TreeDifference expectSameTree(const SvoTree& gpu, const SvoTree& cpu, const TubeModel& model,
                              const std::vector<SvoLeaf>& leaves) {
  TreeDifference diff;
  const SvoGrid& grid = cpu.grid;
  EXPECT_EQ(gpu.leaves, cpu.leaves);
  const std::vector<uint32_t> gs = listStarts(gpu.decoration), cs = listStarts(cpu.decoration);
  EXPECT_EQ(gs.size(), cpu.leaves);
  EXPECT_EQ(cs.size(), cpu.leaves);
  if (gs.size() != cs.size() || gpu.nodes.size() != cpu.nodes.size()) {
    ADD_FAILURE() << "nodes " << gpu.nodes.size() << " vs " << cpu.nodes.size() << ", lists " << gs.size() << " vs "
                  << cs.size();
    return diff;
  }
  size_t bad_nodes = 0;
  for (size_t i = 0; i < cpu.nodes.size(); ++i) {
    const shader::SvoNode& g = gpu.nodes[i];
    const shader::SvoNode& c = cpu.nodes[i];
    bool same = (g.ref & shader::kSvoNodeTypeMask) == (c.ref & shader::kSvoNodeTypeMask) &&
                std::memcmp(&g.distance, &c.distance, 4) == 0;
    if (same && (c.ref & shader::kSvoNodeTypeMask) == shader::kSvoNodeLeaf) {
      const auto gi = std::lower_bound(gs.begin(), gs.end(), g.ref & shader::kSvoNodeIndexMask);
      const auto ci = std::lower_bound(cs.begin(), cs.end(), c.ref & shader::kSvoNodeIndexMask);
      same = gi != gs.end() && ci != cs.end() && *gi == (g.ref & shader::kSvoNodeIndexMask) &&
             *ci == (c.ref & shader::kSvoNodeIndexMask) && gi - gs.begin() == ci - cs.begin();
    } else if (same) {
      same = g.ref == c.ref;
    }
    if (!same && ++bad_nodes <= 5) ADD_FAILURE() << "node " << i << ": " << g.ref << " vs " << c.ref;
  }
  EXPECT_EQ(bad_nodes, 0u);
  // Lists, leaf by leaf (the k-th list is the k-th leaf's: both lay them
  // out in code order).
  const float tolerance = 1e-5f * std::max(1.0f, grid.band());
  size_t bad_lists = 0;
  for (size_t k = 0; k < cs.size(); ++k) {
    const auto g0 = gpu.decoration.begin() + gs[k] + 1, c0 = cpu.decoration.begin() + cs[k] + 1;
    const std::vector<uint32_t> gl(g0, g0 + gpu.decoration[gs[k]]), cl(c0, c0 + cpu.decoration[cs[k]]);
    EXPECT_TRUE(std::is_sorted(gl.begin(), gl.end())) << "list " << k;
    if (gl == cl) continue;
    std::vector<uint32_t> only;
    std::set_symmetric_difference(gl.begin(), gl.end(), cl.begin(), cl.end(), std::back_inserter(only));
    uint32_t x, y, z;
    mortonVoxel(leaves[k].code, grid.levels, x, y, z);
    for (const uint32_t s : only) {
      const float f = std::fabs(segmentDistance(model, grid, s, grid.center(x, y, z)));
      if (std::fabs(f - grid.band()) <= tolerance) {
        ++diff.edge_segments;
      } else if (++bad_lists <= 5) {
        ADD_FAILURE() << "list " << k << ": segment " << s << " at |f| " << f << " (band " << grid.band()
                      << ") in one build only";
      }
    }
  }
  EXPECT_EQ(bad_lists, 0u);
  EXPECT_LE(diff.edge_segments, cpu.references / 1000 + 2) << "band-edge segments";
  if (diff.edge_segments == 0) {
    EXPECT_EQ(gpu.decoration, cpu.decoration);
    EXPECT_EQ(gpu.lod, cpu.lod);
    EXPECT_EQ(gpu.references, cpu.references);
    EXPECT_EQ(gpu.leaves_over_4, cpu.leaves_over_4);
    EXPECT_EQ(gpu.max_segments_per_leaf, cpu.max_segments_per_leaf);
  } else {
    EXPECT_EQ(gpu.lod.size(), cpu.lod.size());
  }
  return diff;
}

// The GPU's leaves, its tree step from them, and buildSvoTree from them.
struct Builds {
  std::vector<SvoLeaf> leaves;
  SvoTree gpu, cpu;
};
Builds buildBoth(const gpu::VulkanContext& context, const TubeModel& model, const SvoGrid& grid) {
  GpuTubes tubes = uploadTubes(context, model);
  Builds out;
  try {
    out.leaves = voxelizeSvoLeavesGpu(context, model, tubes, grid);
    out.gpu = buildSvoTreeGpu(context, model, tubes, grid, out.leaves);
  } catch (...) {
    destroyTubes(context, tubes);
    throw;
  }
  destroyTubes(context, tubes);
  out.cpu = buildSvoTree(model, grid, out.leaves);
  return out;
}

TEST_F(GpuSvoTree, straightTreeAndListsAreTheCpuTreeOnTheSameLeaves) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  const Builds b = buildBoth(context(), model, grid);
  EXPECT_GT(b.cpu.leaves_over_4, 10u);  // lists longer than the seed's 4
  const TreeDifference d = expectSameTree(b.gpu, b.cpu, model, b.leaves);
  std::printf("straight: %zu leaves, %zu references, %zu band-edge segments\n", b.cpu.leaves, b.cpu.references,
              d.edge_segments);
}

TEST_F(GpuSvoTree, curvedTreeAndListsAreTheCpuTreeOnTheSameLeaves) {
  const TubeModel model = buildTubes(test::curvedSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f, true);
  ASSERT_TRUE(grid.curved);
  const Builds b = buildBoth(context(), model, grid);
  EXPECT_GT(b.cpu.leaves, 100u);
  EXPECT_GT(b.cpu.leaves_over_4, 0u);
  const TreeDifference d = expectSameTree(b.gpu, b.cpu, model, b.leaves);
  std::printf("curved: %zu leaves, %zu references, %zu band-edge segments\n", b.cpu.leaves, b.cpu.references,
              d.edge_segments);
}

// Past 2^16 leaves: the list offsets' and the levels' scans take many
// chunks (1,024 words each) and a second level of chunk totals.
TEST_F(GpuSvoTree, aTreePastTwoToTheSixteenLeavesIsTheCpuTree) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.05f);
  const Builds b = buildBoth(context(), model, grid);
  ASSERT_GT(b.cpu.leaves, size_t(1) << 16);
  const TreeDifference d = expectSameTree(b.gpu, b.cpu, model, b.leaves);
  std::printf("fine: %zu leaves, %zu references, %zu band-edge segments\n", b.cpu.leaves, b.cpu.references,
              d.edge_segments);
}

// buildSvoGpu's device path (the sorted leaves never leave the device)
// against buildSvoTree on the leaves voxelizeSvoLeavesGpu downloads, the
// CPU step it runs where asked, and the default's choice (the CPU step on
// a CPU device such as lavapipe, the device step elsewhere).
TEST_F(GpuSvoTree, buildSvoGpuKeepsTheLeavesOnTheDeviceAndGivesTheSameTree) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  GpuTubes tubes = uploadTubes(context(), model);
  SvoTree device, on_cpu;
  std::vector<SvoLeaf> leaves;
  SvoGpuBuildStats st, by_default;
  try {
    leaves = voxelizeSvoLeavesGpu(context(), model, tubes, grid);
    SvoGpuBuildOptions o;
    o.tree_on_cpu = false;
    device = buildSvoGpu(context(), model, tubes, grid, o, &st);
    o.tree_on_cpu = true;
    on_cpu = buildSvoGpu(context(), model, tubes, grid, o);
    buildSvoGpu(context(), model, tubes, grid, {}, &by_default);
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
  expectSameTree(device, buildSvoTree(model, grid, leaves), model, leaves);
  expectSameTree(on_cpu, buildSvoTree(model, grid, leaves), model, leaves);
  EXPECT_GT(st.tree_s, 0.0);
  EXPECT_GT(st.tree_times.lists_s(), 0.0);
  const bool cpu_device = context().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU;
  EXPECT_EQ(by_default.tree_times.lists_s() > 0.0, !cpu_device);
}

// A set cancel flag (the viewer quitting during a build) ends the build
// with one Error naming the cancellation, before its first slab, and the
// same options without it build the tree (the buffers of the cancelled
// build freed: the validation layers see no leak at the context's end).
TEST_F(GpuSvoTree, aCancelledBuildThrowsAtItsNextStep) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  GpuTubes tubes = uploadTubes(context(), model);
  std::atomic<bool> cancel{true};
  SvoGpuBuildOptions o;
  o.cancel = &cancel;
  std::string message;
  SvoTree tree;
  try {
    try {
      buildSvoGpu(context(), model, tubes, grid, o);
    } catch (const Error& e) {
      message = e.what();
    }
    cancel = false;
    tree = buildSvoGpu(context(), model, tubes, grid, o);
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
  EXPECT_NE(message.find("cancelled"), std::string::npos) << message;
  EXPECT_GT(tree.leaves, 0u);
}

TEST_F(GpuSvoTree, noLeavesGiveAnEmptyRoot) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  GpuTubes tubes = uploadTubes(context(), model);
  SvoTree tree;
  try {
    tree = buildSvoTreeGpu(context(), model, tubes, grid, {});
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
  const SvoTree cpu = buildSvoTree(model, grid, {});
  ASSERT_EQ(tree.nodes.size(), 1u);
  EXPECT_EQ(tree.nodes[0].ref, cpu.nodes[0].ref);
  EXPECT_TRUE(tree.decoration.empty());
  EXPECT_TRUE(tree.lod.empty());
}

// Figures for docs/BENCHMARKS.md, not a check: runs only with
// FIBSCOPE_SVO_TREE_BENCH=A.tck,B.tck (radius FIBSCOPE_SVO_TREE_RADIUS,
// 0.5 mm; the voxel by the rule and the density criterion, as render's).
// Per file: the GPU leaves once, then buildSvoTree on the CPU and the
// device's tree step on the same leaves (host clock each, with their
// parts), and whether the two trees agree.
TEST_F(GpuSvoTree, cpuAgainstGpuTreeStepWhenAsked) {
  const char* files = std::getenv("FIBSCOPE_SVO_TREE_BENCH");
  if (!files) GTEST_SKIP() << "set FIBSCOPE_SVO_TREE_BENCH=A.tck,B.tck to measure";
  const char* radius_text = std::getenv("FIBSCOPE_SVO_TREE_RADIUS");
  const float radius = radius_text ? std::strtof(radius_text, nullptr) : 0.5f;
  using Clock = std::chrono::steady_clock;
  std::string list = files;
  for (size_t at = 0; at <= list.size();) {
    const size_t comma = std::min(list.find(',', at), list.size());
    const std::string path = list.substr(at, comma - at);
    at = comma + 1;
    if (path.empty()) continue;
    const Tractogram t = readAllStreamlines(*openTractogram(path));
    const TubeModel model = buildTubes(t, test::svoTubeOptions(radius));
    const SvoGrid grid = chooseSvoGrid(model, 0.0f, false, svoMemoryLimit(context()));
    GpuTubes tubes = uploadTubes(context(), model);
    try {
      SvoGpuBuildStats st;
      const std::vector<SvoLeaf> leaves = voxelizeSvoLeavesGpu(context(), model, tubes, grid, {}, &st);
      SvoTreeTimes ct;
      auto t0 = Clock::now();
      const SvoTree cpu = buildSvoTree(model, grid, leaves, &ct);
      const double cpu_s = std::chrono::duration<double>(Clock::now() - t0).count();
      SvoGpuTreeTimes gt;
      t0 = Clock::now();
      const SvoTree gpu = buildSvoTreeGpu(context(), model, tubes, grid, leaves, {}, &gt);
      const double gpu_s = std::chrono::duration<double>(Clock::now() - t0).count();
      const bool same = gpu.nodes.size() == cpu.nodes.size() && gpu.decoration == cpu.decoration &&
                        gpu.lod == cpu.lod &&
                        std::equal(gpu.nodes.begin(), gpu.nodes.end(), cpu.nodes.begin(),
                                   [](const shader::SvoNode& a, const shader::SvoNode& b) {
                                     return a.ref == b.ref && std::memcmp(&a.distance, &b.distance, 4) == 0;
                                   });
      std::printf("%s: %zu segments, voxel %.3f mm, %u^3, %zu leaves, %zu references; voxelise %.1f s, sort %.1f s\n"
                  "  CPU buildSvoTree %.2f s (pairs %.2f, sort + lists %.2f, layout %.2f, lod %.2f)\n"
                  "  GPU tree step    %.2f s (lists: count %.2f, fill %.2f, sort %.2f; levels + nodes %.2f, download %.2f, "
                  "lod on CPU %.2f)\n"
                  "  CPU / GPU %.2fx, trees %s\n",
                  path.c_str(), model.segments.size(), grid.voxel, grid.side(), cpu.leaves, cpu.references,
                  st.voxelize_s, st.sort_s, cpu_s, ct.pairs_s, ct.sort_s, ct.layout_s, ct.lod_s, gpu_s, gt.count_s,
                  gt.fill_s, gt.sort_s, gt.levels_s, gt.download_s, gt.lod_s, cpu_s / gpu_s, same ? "identical" : "DIFFER");
      std::fflush(stdout);
      if (!same) expectSameTree(gpu, cpu, model, leaves);
    } catch (...) {
      destroyTubes(context(), tubes);
      throw;
    }
    destroyTubes(context(), tubes);
  }
}

}  // namespace
}  // namespace fibscope
