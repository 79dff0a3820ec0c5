// The compute ray casting of spline tubes (src/tubes/gpu, tube_bin_*.comp,
// tube_raycast.comp) against the CPU reference of the same intersection
// (src/tubes/tube_intersect.h, itself tested against the brute-force sphere
// sweep): hit/miss, depth, fiber, normal and position along the fiber per
// pixel in the surface target, on curved test tubes from three views, and
// with tiles whose lists overflow. Validation layers on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/pick.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "tube_test_scenes.h"
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/tube_intersect.h"

namespace fibscope {
namespace {

class GpuTubeRaycast : public test::GpuTest {
 protected:
  // The surface target of one frame of `model` (setup and the tube stage
  // only).
  std::vector<shader::SurfaceTexel> castOnGpu(const TubeModel& model, const Camera& camera,
                                              FrameStats* stats = nullptr) {
    return castFrames(model, camera, {}, 1, stats).back();
  }
  // The surface targets of `frames` frames of `model` by one renderer, and
  // each frame's statistics.
  std::vector<std::vector<shader::SurfaceTexel>> castFrames(const TubeModel& model, const Camera& camera,
                                                            TubeRaycastOptions options, int frames,
                                                            FrameStats* stats) {
    GpuTubes tubes = uploadTubes(context(), model);
    std::vector<std::vector<shader::SurfaceTexel>> surface;
    try {
      // The compute pipeline's frame over no datasets: no geometry stage.
      FrameRenderer renderer(context(), camera.width, camera.height,
                             {makeSetupStage, tubeRaycastStage(&tubes, options)});
      for (int f = 0; f < frames; ++f) {
        const FrameStats frame = renderer.render(camera, RenderSettings(), GpuScene());
        if (stats) stats[f] = frame;
        surface.push_back(downloadSurface(context(), renderer.targets()));
      }
    } catch (...) {
      destroyTubes(context(), tubes);
      throw;
    }
    destroyTubes(context(), tubes);
    return surface;
  }
};

struct Agreement {
  size_t either = 0, disagree = 0, both = 0, fiber_mismatch = 0;
  double max_depth_mm = 0, max_normal_error = 0, max_position_error = 0;
  double agreement() const { return either ? 1.0 - double(disagree) / double(either) : 1.0; }
  std::string summary() const {
    return std::to_string(both) + " pixels both, " + std::to_string(disagree) + " of " + std::to_string(either) +
           " disagree, depth error " + std::to_string(max_depth_mm) + " mm, normal " +
           std::to_string(max_normal_error) + ", position " + std::to_string(max_position_error);
  }
};

Agreement compare(const std::vector<shader::SurfaceTexel>& gpu, const TubeReferenceImage& ref, const Camera& camera) {
  const std::array<double, 16> view = viewMatrixD(camera);
  const glm::dvec3 forward(-view[2], -view[6], -view[10]);
  const double n = camera.near_mm, f = camera.far_mm;
  Agreement a;
  for (size_t i = 0; i < gpu.size(); ++i) {
    const bool hg = gpu[i].depth < 1.0f, hr = ref.fiber[i] != shader::kNoFiberId;
    if (!hg && !hr) continue;
    ++a.either;
    if (hg != hr) {
      ++a.disagree;
      continue;
    }
    ++a.both;
    if (gpu[i].fiber != ref.fiber[i]) ++a.fiber_mismatch;
    EXPECT_EQ(gpu[i].source, shader::kSurfaceSourceTube);
    // View-axis distances: the GPU's from its clip depth (camera.cpp's
    // projection), the reference's from its ray distance.
    const uint32_t px = uint32_t(i % camera.width), py = uint32_t(i / camera.width);
    glm::dvec3 o, d;
    tubePixelRay(camera, px, py, o, d);
    const double z_gpu = n * f / (f - double(gpu[i].depth) * (f - n));
    const double z_ref = ref.distance[i] * glm::dot(d, forward);
    a.max_depth_mm = std::max(a.max_depth_mm, std::fabs(z_gpu - z_ref));
    const std::array<float, 3> g = test::unpackTangent(gpu[i].normal);
    a.max_normal_error =
        std::max(a.max_normal_error, double(glm::distance(glm::vec3(g[0], g[1], g[2]), ref.normal[i])));
    a.max_position_error = std::max(a.max_position_error, double(std::fabs(gpu[i].position - ref.position[i])));
  }
  return a;
}

TEST_F(GpuTubeRaycast, computeRayCastingMatchesTheCpuReferenceOnCurvedTubes) {
  for (const test::TubeScene& scene : test::tubeScenes()) {
    const TubeModel model = buildTubes(scene.tractogram, scene.options);
    for (const Camera& camera : test::tubeSceneCameras(scene, 120, 90)) {
      const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
      FrameStats stats;
      const Agreement a = compare(castOnGpu(model, camera, &stats), ref, camera);
      EXPECT_EQ(stats.tube_tiles_overflowed, 0u);
      const std::string what = scene.name + " from (" + std::to_string(camera.eye[0]) + ", " +
                               std::to_string(camera.eye[1]) + ", " + std::to_string(camera.eye[2]) +
                               "): " + a.summary();
      EXPECT_GT(a.both, 250u) << what;
      EXPECT_GE(a.agreement(), 0.98) << what;
      EXPECT_EQ(a.fiber_mismatch, 0u) << what;
      EXPECT_LE(a.max_depth_mm, 1e-4 * scene.min_radius) << what;
      EXPECT_LE(a.max_normal_error, 1e-2) << what;  // measured: 4e-3 (t from 10 bisections)
      EXPECT_LE(a.max_position_error, 5e-3) << what;
    }
  }
}

// 300 short tubes piled in the same few tiles: up to 1,200 sub-segments a
// tile.
Tractogram pileOfTubes() {
  Tractogram t;
  for (int i = 0; i < 300; ++i) {
    const float a = float(i) * 0.02f, z = float(i) * 0.008f;
    const float xyz[] = {-2.0f * std::cos(a), -2.0f * std::sin(a), z, 0.0f, 0.3f * std::sin(3.0f * a), z,
                         2.0f * std::cos(a),  2.0f * std::sin(a),  z};
    t.addStreamline(xyz, 3);
  }
  return t;
}

// The lists held to 64 items: the tiles that do not fit test every
// sub-segment and still draw every tube.
TEST_F(GpuTubeRaycast, tilesWhoseListsOverflowStillDrawEveryTube) {
  const Tractogram t = pileOfTubes();
  TubeBuildOptions o;
  o.radius.radius = 0.1f;
  const TubeModel model = buildTubes(t, o);
  ASSERT_GT(model.subSegmentCount(), size_t(64));
  const Camera camera = fitCamera(tractogramBounds(t), {0.2, -0.3, 1}, {0, 1, 0}, 48, 48);
  const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
  FrameStats stats[2];
  const auto frames = castFrames(model, camera, TubeRaycastOptions{64 * sizeof(uint32_t)}, 2, stats);
  for (int f = 0; f < 2; ++f) {
    EXPECT_GT(stats[f].tube_tiles_overflowed, 0u) << "frame " << f << ": the limit holds";
    const Agreement a = compare(frames[f], ref, camera);
    EXPECT_GT(a.both, 300u) << a.summary();
    EXPECT_GE(a.agreement(), 0.98) << a.summary();
    EXPECT_LE(a.fiber_mismatch, a.both / 50) << a.summary();  // tubes overlapping within float depth
  }
}

// An 8 x 8 frame is one tile, whose first list holds kTubeTileCapacity
// items, fewer than the pile puts there: the first frame overflows, the
// lists grow to its total, and the second frame fits with the same texels
// (both equal to the reference).
TEST_F(GpuTubeRaycast, listsGrowToTheFramesTotal) {
  const Tractogram t = pileOfTubes();
  TubeBuildOptions o;
  o.radius.radius = 0.1f;
  const TubeModel model = buildTubes(t, o);
  const Camera camera = fitCamera(tractogramBounds(t), {0.2, -0.3, 1}, {0, 1, 0}, 8, 8);
  FrameStats stats[3];
  const auto frames = castFrames(model, camera, {}, 3, stats);
  EXPECT_EQ(stats[0].tube_tiles_overflowed, 1u);
  EXPECT_EQ(stats[1].tube_tiles_overflowed, 0u);
  EXPECT_EQ(stats[2].tube_tiles_overflowed, 0u);
  EXPECT_GT(stats[1].tube_method_bytes, stats[0].tube_method_bytes);
  EXPECT_EQ(stats[2].tube_method_bytes, stats[1].tube_method_bytes);
  const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
  for (int f = 0; f < 3; ++f) {
    const Agreement a = compare(frames[f], ref, camera);
    EXPECT_GT(a.both, 16u) << a.summary();
    EXPECT_GE(a.agreement(), 0.98) << a.summary();
  }
  EXPECT_EQ(0, std::memcmp(frames[0].data(), frames[1].data(), frames[0].size() * sizeof(frames[0][0])));
}

// Lines along x in the plane z = 0 and tubes above them, below them and
// through them (seen from +z): with the standard stages and the tube stage,
// for every tube method (compute and fragment ray casting, tessellation;
// the same test for all three) in the compute and raw-compute pipelines,
// the G-buffer's tube pixels (kGBufferSurface | kSurfaceSourceTube) are
// where the reference tube is nearer than the reference lines, and the
// lines' where they are nearer.
TEST_F(GpuTubeRaycast, tubesAndLinesOccludeEachOtherBothWaysAsTheReferencesForEveryMethod) {
  const test::LinesAndTubesScene setup = test::linesAndTubesScene(0.25f, 128, 96);
  const Tractogram& lines = setup.lines;
  const TubeModel model = buildTubes(setup.tubes, setup.options);
  constexpr uint32_t w = 128, h = 96;
  const Camera& camera = setup.camera;
  const ReferenceFrame line_ref = rasterizeReference(lines, camera, 2.0f);
  const TubeReferenceImage tube_ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
  std::vector<uint8_t> want_tube(size_t(w) * h), want_line(size_t(w) * h);
  size_t lines_over_tubes = 0, tubes_over_lines = 0;
  for (size_t i = 0; i < want_tube.size(); ++i) {
    const bool t = tube_ref.fiber[i] != shader::kNoFiberId, l = line_ref.fiber[i] != kNoFiber;
    want_tube[i] = t && (!l || tube_ref.depth[i] < line_ref.depth[i]);
    want_line[i] = l && !want_tube[i];
    lines_over_tubes += t && want_line[i];
    tubes_over_lines += l && want_tube[i];
  }
  // The scene shows both ways.
  ASSERT_GT(lines_over_tubes, 100u);
  ASSERT_GT(tubes_over_lines, 100u);

  const TractogramUpload upload = uploadTractogram(context(), lines, "lines");
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), lines, "lines");
  GpuTubes tubes = uploadTubes(context(), model);
  try {
    FrameRenderer renderer(context(), w, h, withTubeStage(standardFrameStages(), &tubes));
    const GpuScene scene(&upload.dataset, &raw);
    const std::pair<TubeMethod, const char*> methods[] = {
        {TubeMethod::Compute, "tube raycast"}, {TubeMethod::Raycast, "tube boxes"}, {TubeMethod::Tessellation, "tube tess"}};
    for (const auto& [method, pass] : methods)
    for (const RenderPipeline pipeline : {RenderPipeline::Compute, RenderPipeline::RawCompute}) {
      SCOPED_TRACE(std::string(tubeMethodName(method)) + " over " + std::string(renderPipelineName(pipeline)));
      RenderSettings settings;
      settings.pipeline = pipeline;
      settings.tube_method = method;
      settings.line_width_px = 2.0f;
      const FrameStats stats = renderer.render(camera, settings, scene);
      const auto texels = downloadGBuffer(context(), renderer.targets());
      std::vector<uint8_t> got_tube, got_line;
      for (const shader::GBufferTexel& t : texels) {
        const bool tube = t.segment == (shader::kGBufferSurface | shader::kSurfaceSourceTube);
        got_tube.push_back(tube);
        got_line.push_back(!tube && t.fiber != shader::kNoFiberId);
      }
      const CoverageComparison ct = compareCoverage(got_tube, want_tube, w, h);
      const CoverageComparison cl = compareCoverage(got_line, want_line, w, h);
      EXPECT_GE(ct.agreement, 0.98) << "tubes: " << ct.summary();
      EXPECT_LE(ct.maxDistance(), 1.0) << "tubes: " << ct.summary();
      EXPECT_GE(cl.agreement, 0.98) << "lines: " << cl.summary();
      EXPECT_LE(cl.maxDistance(), 1.0) << "lines: " << cl.summary();
      bool timed = false;
      for (const PassTiming& p : stats.passes) timed |= p.name == pass;
      EXPECT_TRUE(timed) << pass;
      // Picking a tube pixel names the tube's fiber and the source.
      for (size_t i = 0; i < got_tube.size(); ++i)
        if (got_tube[i] && want_tube[i] && tube_ref.fiber[i] == 1u) {
          const PickResult pick = pickFiber(context(), renderer.targets(), uint32_t(i % w), uint32_t(i / w));
          EXPECT_TRUE(pick.hit && pick.surface);
          EXPECT_EQ(pick.fiber, 1u);
          EXPECT_EQ(pick.source, shader::kSurfaceSourceTube);
          break;
        }
    }
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
}

TEST_F(GpuTubeRaycast, anEmptyModelUploadsNothing) {
  const TubeModel model = buildTubes(Tractogram(), {});
  GpuTubes tubes = uploadTubes(context(), model);
  EXPECT_EQ(tubes.segment_count, 0u);
  EXPECT_EQ(tubes.nodes.buffer, VK_NULL_HANDLE);
  destroyTubes(context(), tubes);
}

// Issue 15 item 6: a fiber of one point is drawn, as a sphere of the radius.
TEST_F(GpuTubeRaycast, aFiberOfOnePointIsDrawnAsASphereAsTheReference) {
  Tractogram t;
  const float one[] = {0, 0, 0};
  t.addStreamline(one, 1);
  TubeBuildOptions o;
  o.radius.radius = 2.0f;
  const TubeModel model = buildTubes(t, o);
  Camera camera;
  camera.eye = {3, 4, 30};
  camera.width = 64;
  camera.height = 64;
  camera.near_mm = 20;
  camera.far_mm = 40;
  const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
  const std::vector<shader::SurfaceTexel> surface = castOnGpu(model, camera);
  const Agreement a = compare(surface, ref, camera);
  // No centre line direction: the tangent (orientation colour) is the normal.
  for (const shader::SurfaceTexel& t : surface)
    if (t.depth < 1.0f) ASSERT_EQ(t.tangent, t.normal);
  // A disk of 2 mm at 30.4 mm in a 30 degree, 64 px frame: radius 7.9 px,
  // about 194 pixels.
  EXPECT_NEAR(double(a.both), 194.0, 20.0) << a.summary();
  EXPECT_GE(a.agreement(), 0.98) << a.summary();
  EXPECT_LE(a.max_depth_mm, 2e-4) << a.summary();
  // The reference is the sphere: its nearest point is 2 mm before the centre.
  const double centre = std::sqrt(9.0 + 16.0 + 900.0);
  double nearest = 1e9;
  for (size_t i = 0; i < ref.distance.size(); ++i)
    if (ref.fiber[i] == 0u) nearest = std::min(nearest, ref.distance[i]);
  EXPECT_NEAR(nearest, centre - 2.0, 0.05);
}

}  // namespace
}  // namespace fibscope
