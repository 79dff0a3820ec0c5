// The SVO trace's level of detail (shared/svo.h SvoTracePush::lod_px,
// issue 16 item 3): off, it is the exact walk bit for bit; on, in a far
// view, it stays within the stated bound of the brute-force ray-capsule
// reference (every reference pixel covered, extra coverage within a node
// around the tubes, depth within the node's diagonal, hit points within a
// node of a tube surface, most fiber ids the same), and its walk visits
// fewer nodes and tests fewer segments (the trace's stat counters).
// Validation layers on.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "gpu/buffer.h"
#include "gpu_test_context.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/frame_targets.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "svo/gpu/gpu_svo.h"
#include "svo/svo_build.h"
#include "svo/svo_reference.h"
#include "svo_test_scenes.h"

namespace fibscope {
namespace {

class GpuSvoLod : public test::GpuTest {};

struct LodFrame {
  std::vector<shader::SurfaceTexel> surface;
  uint32_t visits = 0, tests = 0;  // the walk's node visits and segment tests (SvoTraceOptions::stats)
};

// One build of `model` on `grid`, one frame per LoD threshold (a renderer
// each: the trace's options are the stage's), all with the stat counters.
std::vector<LodFrame> traceWithLods(const gpu::VulkanContext& context, const TubeModel& model, const SvoGrid& grid,
                                    const Camera& camera, const std::vector<float>& lods, SvoTree* tree_out = nullptr) {
  GpuTubes tubes = uploadTubes(context, model);
  GpuSvo svo;
  gpu::Buffer stats = gpu::createBuffer(context, 8, gpu::MemoryUse::Readback);
  std::vector<LodFrame> frames;
  try {
    const SvoTree tree = buildSvoGpu(context, model, tubes, grid);
    if (tree_out) *tree_out = tree;
    svo = uploadSvo(context, tree);
    for (const float lod : lods) {
      const uint32_t zero[2] = {0, 0};
      gpu::uploadToBuffer(context, stats, zero, sizeof(zero));
      FrameRenderer renderer(context, camera.width, camera.height,
                             {makeSetupStage, svoTraceStage(&svo, &tubes, SvoTraceOptions{lod, stats.address})});
      renderer.render(camera, RenderSettings(), GpuScene());
      LodFrame f;
      f.surface = downloadSurface(context, renderer.targets());
      uint32_t counts[2];
      gpu::downloadFromBuffer(context, stats, counts, sizeof(counts));
      f.visits = counts[0];
      f.tests = counts[1];
      frames.push_back(std::move(f));
    }
  } catch (...) {
    gpu::destroyBuffer(context, stats);
    destroySvo(context, svo);
    destroyTubes(context, tubes);
    throw;
  }
  gpu::destroyBuffer(context, stats);
  destroySvo(context, svo);
  destroyTubes(context, tubes);
  return frames;
}

// The stage as every other caller makes it (default options: no LoD, no
// counters).
std::vector<shader::SurfaceTexel> traceDefault(const gpu::VulkanContext& context, const TubeModel& model,
                                               const SvoGrid& grid, const Camera& camera) {
  GpuTubes tubes = uploadTubes(context, model);
  GpuSvo svo;
  std::vector<shader::SurfaceTexel> surface;
  try {
    svo = uploadSvo(context, buildSvoGpu(context, model, tubes, grid));
    FrameRenderer renderer(context, camera.width, camera.height, {makeSetupStage, svoTraceStage(&svo, &tubes)});
    renderer.render(camera, RenderSettings(), GpuScene());
    surface = downloadSurface(context, renderer.targets());
  } catch (...) {
    destroySvo(context, svo);
    destroyTubes(context, tubes);
    throw;
  }
  destroySvo(context, svo);
  destroyTubes(context, tubes);
  return surface;
}

bool sameTexels(const std::vector<shader::SurfaceTexel>& a, const std::vector<shader::SurfaceTexel>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0;
}

double viewZ(const Camera& c, double depth) { return c.near_mm * c.far_mm / (c.far_mm - depth * (c.far_mm - c.near_mm)); }

// A pixel's footprint per mm of distance, as the stage computes it.
double pixelAngle(const Camera& c) { return 2.0 * std::tan(0.5 * c.fov_y_deg * M_PI / 180.0) / double(c.height); }

TEST_F(GpuSvoLod, lodOffIsTheExactWalkBitForBit) {
  const Tractogram t = test::denseSvoBundle();
  const TubeModel model = buildTubes(t, test::svoTubeOptions(0.3f));
  for (const bool curved : {false, true}) {
    const SvoGrid grid = chooseSvoGrid(model, 0.0f, curved);
    const Camera camera = test::svoCamera(t, 0.3, -1.0, 0.6, 80, 64);
    // The smallest internal node (2 voxels) spans far more than 1e-3 px
    // even at the far plane: that threshold never stops a ray, so its
    // frame runs the LoD's code path without a stop.
    ASSERT_GT(2.0 * grid.voxel / (pixelAngle(camera) * camera.far_mm), 1e-3);
    const std::vector<LodFrame> frames = traceWithLods(context(), model, grid, camera, {0.0f, 1e-3f});
    const std::vector<shader::SurfaceTexel> plain = traceDefault(context(), model, grid, camera);
    size_t covered = 0;
    for (const shader::SurfaceTexel& s : plain) covered += s.depth < 1.0f;
    EXPECT_GT(covered, 500u) << (curved ? "curved" : "straight");
    EXPECT_TRUE(sameTexels(frames[0].surface, plain)) << (curved ? "curved" : "straight") << ": lod 0 with counters";
    EXPECT_TRUE(sameTexels(frames[1].surface, plain)) << (curved ? "curved" : "straight") << ": lod 1e-3 px";
    EXPECT_EQ(frames[0].visits, frames[1].visits);
    EXPECT_EQ(frames[0].tests, frames[1].tests);
    EXPECT_GT(frames[0].visits, 0u);
  }
}

// Far views of the dense bundle (straight) and of the curved arcs, lod 3
// px, against the brute-force reference (curved: each cubic as 32
// capsules, as gpu_svo_test.cpp). The bound (shared/svo.h), per pixel with
// f = the footprint of a pixel at the hit's distance t (pixel_angle * t):
// a stopped node's edge e < lod_px f (the stop is at t0 <= t), e a power
// of two voxels: D = sqrt(3) e for the largest such e. Coverage: every reference pixel covered (the
// walk still reaches the reference's surface or stops in front of it;
// curved: but the exact curved trace's own 1 % of grazing pixels); an
// extra pixel's ray passes through a non-empty node, whose box holds a
// leaf centre within the band b of a surface point: within D + b of it,
// so within D / f + b / f + 1 pixels (the 1: that point's own tube covers
// pixel centres within a pixel of it) of a reference pixel. Depth: the
// walk found no surface before the node's entry, so the LoD hit lies
// nowhere behind the reference's by more than the node's chord (<= D);
// every LoD hit point lies within D + b of a tube surface (its distance to
// the nearest capsule). Measured, not bounded: the fraction of pixels
// within D of the reference's depth (the reference's hit in the stopped
// node) and of the same fiber.
TEST_F(GpuSvoLod, farViewStaysWithinTheStatedBound) {
  for (const bool curved : {false, true}) {
    const Tractogram t = curved ? test::curvedSvoBundle() : test::denseSvoBundle();
    const TubeModel model = buildTubes(t, test::svoTubeOptions(0.3f));
    const TubeModel reference_model = curved ? test::subdivideCurvedTubes(model, 32) : model;
    const SvoGrid grid = chooseSvoGrid(model, 0.0f, curved);
    const Bounds bounds = tractogramBounds(t);
    const Camera camera = fitCamera(bounds, {0.3, -1.0, 0.6}, {0, 0, 1}, 128, 128, 3.0);
    const float lod_px = 3.0f;
    SvoTree tree;
    const std::vector<LodFrame> frames = traceWithLods(context(), model, grid, camera, {0.0f, lod_px}, &tree);
    const std::vector<shader::SurfaceTexel>& exact = frames[0].surface;
    const std::vector<shader::SurfaceTexel>& lod = frames[1].surface;
    const TubeReferenceImage ref = renderBruteForceCapsules(reference_model, camera);
    const std::array<double, 16> view = viewMatrixD(camera);
    const glm::dvec3 forward(-view[2], -view[6], -view[10]);
    const double pa = pixelAngle(camera), band = grid.band();
    const uint32_t w = camera.width, h = camera.height;
    const char* what = curved ? "curved" : "straight";

    // The far view does stop: a 2-voxel node is below 3 px at the scene.
    glm::dvec3 o0, d0;
    tubePixelRay(camera, w / 2, h / 2, o0, d0);
    const double centre_distance = glm::length(glm::dvec3(bounds.min[0] + bounds.max[0], bounds.min[1] + bounds.max[1],
                                                          bounds.min[2] + bounds.max[2]) * 0.5 - o0);
    ASSERT_LT(2.0 * grid.voxel, lod_px * pa * (centre_distance - 10.0)) << what;
    ASSERT_EQ(tree.lodBytes(), (tree.nodes.size() - 1) / 8 * 4) << what;

    // Reference-covered pixels and, per pixel, the distance (px) to the
    // nearest one (brute force over the small frame).
    std::vector<size_t> covered_ref;
    for (size_t i = 0; i < ref.fiber.size(); ++i)
      if (ref.fiber[i] != shader::kNoFiberId) covered_ref.push_back(i);
    ASSERT_GT(covered_ref.size(), 150u) << what;
    auto distanceToReference = [&](size_t i) {
      double best = INFINITY;
      for (const size_t j : covered_ref) {
        const double dx = double(i % w) - double(j % w), dy = double(i / w) - double(j / w);
        best = std::min(best, std::sqrt(dx * dx + dy * dy));
      }
      return best;
    };
    size_t lost = 0, missed = 0, exact_missed = 0, extra = 0, both = 0, same_fiber = 0, within_diagonal = 0, lod_pixels = 0;
    double worst_extra = 0, worst_behind = -INFINITY, worst_off_surface = -INFINITY;
    for (size_t i = 0; i < lod.size(); ++i) {
      const bool hr = ref.fiber[i] != shader::kNoFiberId, hl = lod[i].depth < 1.0f;
      exact_missed += hr && !(exact[i].depth < 1.0f);
      lost += exact[i].depth < 1.0f && !hl;
      if (!hl) {
        missed += hr;
        continue;
      }
      ++lod_pixels;
      glm::dvec3 o, d;
      tubePixelRay(camera, uint32_t(i % w), uint32_t(i / w), o, d);
      const double cosine = glm::dot(d, forward);
      const double t_lod = viewZ(camera, lod[i].depth) / cosine;
      const double footprint = pa * t_lod;
      // The largest node that can stop here: edges are voxel * 2^k, and
      // below lod_px footprints.
      double edge = grid.voxel;
      while (2.0 * edge < lod_px * footprint) edge *= 2.0;
      const double diagonal = std::sqrt(3.0) * edge;
      // The hit point's distance to the nearest tube surface, past D + b.
      const glm::dvec3 p = o + t_lod * d;
      double f = INFINITY;
      for (const shader::TubeSegment& s : reference_model.segments)
        f = std::min(f, double(capsuleDistance(svoCapsule(reference_model, s), glm::vec3(p))));
      worst_off_surface = std::max(worst_off_surface, std::fabs(f) - (diagonal + band));
      if (!hr) {
        ++extra;
        const double allowed = (diagonal + band) / footprint + 1.0;
        worst_extra = std::max(worst_extra, distanceToReference(i) - allowed);
        continue;
      }
      ++both;
      same_fiber += lod[i].fiber == ref.fiber[i];
      worst_behind = std::max(worst_behind, (t_lod - ref.distance[i]) - diagonal);
      within_diagonal += std::fabs(t_lod - ref.distance[i]) <= diagonal;
    }
    char line[512];
    std::snprintf(line, sizeof(line),
                  "%s, lod %.0f px, voxel %.3f mm, footprint %.3f mm at the centre: %zu reference pixels, %zu "
                  "missed (exact: %zu), %zu of the exact's lost, %zu extra (worst %.2f px past the bound), %zu both: %.1f %% the same fiber, "
                  "%.1f %% within the diagonal of the reference's depth (worst %.3f mm past it behind), hit points "
                  "at worst %.3f mm past D + b from a surface; nodes visited %u -> %u (x%.2f), segments tested %u "
                  "-> %u (x%.2f); lod %zu bytes beside nodes %zu + decoration %zu",
                  what, double(lod_px), double(grid.voxel), pa * centre_distance, covered_ref.size(), missed,
                  exact_missed, lost, extra, worst_extra, both, 100.0 * double(same_fiber) / double(std::max<size_t>(both, 1)),
                  100.0 * double(within_diagonal) / double(std::max<size_t>(both, 1)), worst_behind, worst_off_surface,
                  frames[0].visits, frames[1].visits, double(frames[0].visits) / double(std::max(frames[1].visits, 1u)),
                  frames[0].tests, frames[1].tests, double(frames[0].tests) / double(std::max(frames[1].tests, 1u)),
                  tree.lodBytes(), tree.nodeBytes(), tree.decorationBytes());
    std::printf("%s\n", line);
    // Coverage: every pixel the exact walk covers stays covered, so the
    // reference's pixels are missed no more than the exact trace misses
    // them (its grazing pixels: none straight, <= 1 % curved); the extra
    // within the bound.
    EXPECT_EQ(lost, 0u) << line;
    EXPECT_LE(missed, exact_missed) << line;
    EXPECT_LE(exact_missed, covered_ref.size() / 100) << line;
    EXPECT_LE(worst_extra, 0.0) << line;
    // Depth: never behind the reference by more than the node's diagonal
    // (1e-3 mm: the walk's slack), every hit point within D + b of a tube.
    EXPECT_LE(worst_behind, 1e-3) << line;
    EXPECT_LE(worst_off_surface, 1e-3) << line;
    // Measured figures held to stated floors (lavapipe: within D 79.6 %
    // straight, 87.7 % curved; the same fiber 43.9 % and 62.1 %: the dense
    // bundle packs 24 fibers closer than a diameter, so a 3 px node holds
    // several and its one representative is the front one only in part).
    EXPECT_GE(double(within_diagonal), 0.75 * double(both)) << line;
    EXPECT_GE(double(same_fiber), 0.35 * double(both)) << line;
    // The stops save work (counted, not timed).
    EXPECT_LT(frames[1].visits, frames[0].visits) << line;
    EXPECT_LT(frames[1].tests, frames[0].tests) << line;
  }
}

}  // namespace
}  // namespace fibscope
