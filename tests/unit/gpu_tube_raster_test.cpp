// The fragment-shader ray casting of spline tubes (tube_raster_stage.h:
// instanced tight boxes, tube_box.vert / tube_box.frag, then
// tube_raster_resolve.comp) against the CPU reference of the intersection
// (src/tubes/tube_intersect.h) and against the compute variant
// (tubeRaycastStage) texel for texel; the method-switching tube stage; an
// empty model (tubes and lines occluding each other: gpu_tube_raycast_test.cpp,
// for every method). Validation layers on; frames <= 160 x 120.
// With FIBSCOPE_TUBE_BENCH=1, one more test times both variants on 300
// phantom tubes at 800 x 600 (docs/BENCHMARKS.md).
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "tube_test_scenes.h"
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/gpu/tube_raster_stage.h"
#include "tubes/tube_intersect.h"

namespace fibscope {
namespace {

using StageMaker = std::function<FrameStageFactory(const GpuTubes*)>;

// The compute caster with its default lists.
FrameStageFactory computeCaster(const GpuTubes* tubes) { return tubeRaycastStage(tubes); }

class GpuTubeRaster : public test::GpuTest {
 protected:
  // The surface target of one frame of `model` (setup and the tube stage
  // that `make` gives only).
  std::vector<shader::SurfaceTexel> cast(const TubeModel& model, const Camera& camera, StageMaker make,
                                         FrameStats* stats = nullptr) {
    GpuTubes tubes = uploadTubes(context(), model);
    std::vector<shader::SurfaceTexel> surface;
    try {
      FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, make(&tubes)});
      const FrameStats frame = renderer.render(camera, RenderSettings(), GpuScene());
      if (stats) *stats = frame;
      surface = downloadSurface(context(), renderer.targets());
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

// As gpu_tube_raycast_test.cpp's: the GPU texels against the CPU reference.
Agreement compareWithReference(const std::vector<shader::SurfaceTexel>& gpu, const TubeReferenceImage& ref,
                               const Camera& camera) {
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

// Texel for texel: the fragment variant's surface target against the
// compute variant's.
struct Identity {
  size_t covered = 0, mask_mismatch = 0, fiber_mismatch = 0, depth_over_ulp = 0, other_mismatch = 0;
  uint32_t max_depth_ulps = 0;
  std::string summary() const {
    return std::to_string(covered) + " covered, " + std::to_string(mask_mismatch) + " hit/miss differ, " +
           std::to_string(fiber_mismatch) + " fibers differ, " + std::to_string(depth_over_ulp) +
           " depths > 1 ulp apart (max " + std::to_string(max_depth_ulps) + " ulp), " + std::to_string(other_mismatch) +
           " other fields differ";
  }
};

Identity compareVariants(const std::vector<shader::SurfaceTexel>& raster,
                         const std::vector<shader::SurfaceTexel>& compute) {
  Identity id;
  EXPECT_EQ(raster.size(), compute.size());
  for (size_t i = 0; i < std::min(raster.size(), compute.size()); ++i) {
    const shader::SurfaceTexel &r = raster[i], &c = compute[i];
    const bool hr = r.depth < 1.0f, hc = c.depth < 1.0f;
    id.covered += hr || hc;
    if (hr != hc) {
      ++id.mask_mismatch;
      continue;
    }
    if (!hr) continue;
    if (r.fiber != c.fiber) {
      ++id.fiber_mismatch;
      continue;
    }
    const uint32_t br = std::bit_cast<uint32_t>(r.depth), bc = std::bit_cast<uint32_t>(c.depth);
    const uint32_t ulps = br > bc ? br - bc : bc - br;
    id.max_depth_ulps = std::max(id.max_depth_ulps, ulps);
    id.depth_over_ulp += ulps > 1;
    id.other_mismatch += r.normal != c.normal || r.tangent != c.tangent || r.position != c.position ||
                         r.color != c.color || r.source != c.source;
  }
  return id;
}

std::string cameraName(const Camera& camera) {
  return "from (" + std::to_string(camera.eye[0]) + ", " + std::to_string(camera.eye[1]) + ", " +
         std::to_string(camera.eye[2]) + ")";
}

TEST_F(GpuTubeRaster, fragmentRayCastingMatchesTheCpuReferenceOnCurvedTubes) {
  for (const test::TubeScene& scene : test::tubeScenes()) {
    const TubeModel model = buildTubes(scene.tractogram, scene.options);
    for (const Camera& camera : test::tubeSceneCameras(scene, 120, 90)) {
      const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
      FrameStats stats;
      const Agreement a = compareWithReference(cast(model, camera, tubeRasterRaycastStage, &stats), ref, camera);
      const std::string what = scene.name + " " + cameraName(camera) + ": " + a.summary();
      // The same bounds as the compute variant's test.
      EXPECT_GT(a.both, 250u) << what;
      EXPECT_GE(a.agreement(), 0.98) << what;
      EXPECT_EQ(a.fiber_mismatch, 0u) << what;
      EXPECT_LE(a.max_depth_mm, 1e-4 * scene.min_radius) << what;
      EXPECT_LE(a.max_normal_error, 1e-2) << what;
      EXPECT_LE(a.max_position_error, 5e-3) << what;
      bool timed_boxes = false, timed_resolve = false;
      for (const PassTiming& p : stats.passes) {
        timed_boxes |= p.name == "tube boxes";
        timed_resolve |= p.name == "tube resolve";
      }
      EXPECT_TRUE(timed_boxes && timed_resolve);
    }
  }
}

void expectSameTexels(const Identity& id, const std::string& what) {
  EXPECT_GT(id.covered, 100u) << what << ": " << id.summary();
  EXPECT_EQ(id.mask_mismatch, 0u) << what << ": " << id.summary();
  EXPECT_EQ(id.fiber_mismatch, 0u) << what << ": " << id.summary();
  EXPECT_EQ(id.depth_over_ulp, 0u) << what << ": " << id.summary();
  EXPECT_EQ(id.other_mismatch, 0u) << what << ": " << id.summary();
}

TEST_F(GpuTubeRaster, fragmentAndComputeVariantsWriteTheSameTexelsOnCurvedTubes) {
  for (const test::TubeScene& scene : test::tubeScenes()) {
    const TubeModel model = buildTubes(scene.tractogram, scene.options);
    for (const Camera& camera : test::tubeSceneCameras(scene, 120, 90)) {
      const Identity id =
          compareVariants(cast(model, camera, tubeRasterRaycastStage), cast(model, camera, computeCaster));
      expectSameTexels(id, scene.name + " " + cameraName(camera));
    }
  }
}

TEST_F(GpuTubeRaster, fragmentAndComputeVariantsWriteTheSameTexelsOnAOnePointSphere) {
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
  const std::vector<shader::SurfaceTexel> raster = cast(model, camera, tubeRasterRaycastStage);
  expectSameTexels(compareVariants(raster, cast(model, camera, computeCaster)), "one-point sphere");
  const Agreement a =
      compareWithReference(raster, renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade), camera);
  EXPECT_NEAR(double(a.both), 194.0, 20.0) << a.summary();  // a disk of radius 7.9 px
  EXPECT_LE(a.max_depth_mm, 2e-4) << a.summary();
}

// The tube stage (tubeStage: the method by RenderSettings::tube_method,
// frame to frame in one renderer) draws what each ray-casting method's own
// stage draws, texel for texel, the tessellated tubes where the compute
// caster draws, and switching back gives the first frame again.
TEST_F(GpuTubeRaster, theTubeStageSwitchesMethodsFrameToFrameAsTheirOwnStagesDraw) {
  const test::TubeScene scene = test::tubeScenes().front();  // a copy: tubeScenes() returns by value
  const TubeModel model = buildTubes(scene.tractogram, scene.options);
  const Camera camera = test::tubeSceneCameras(scene, 96, 72).front();
  const std::vector<shader::SurfaceTexel> compute = cast(model, camera, computeCaster);
  const std::vector<shader::SurfaceTexel> raster = cast(model, camera, tubeRasterRaycastStage);
  GpuTubes tubes = uploadTubes(context(), model);
  try {
    FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, tubeStage(&tubes)});
    const auto frame = [&](TubeMethod method, const char* pass) {
      RenderSettings settings;
      settings.tube_method = method;
      const FrameStats stats = renderer.render(camera, settings, GpuScene());
      bool timed = false;
      for (const PassTiming& p : stats.passes) timed |= p.name == pass;
      EXPECT_TRUE(timed) << pass;
      return downloadSurface(context(), renderer.targets());
    };
    expectSameTexels(compareVariants(frame(TubeMethod::Compute, "tube raycast"), compute), "compute");
    expectSameTexels(compareVariants(frame(TubeMethod::Raycast, "tube boxes"), raster), "raycast");
    // Tessellated cylinders are not the ray casters' sphere-swept tubes
    // texel for texel (faceting, gpu_tube_tess_test.cpp bounds it): the
    // same fibers where both cover, nearly the same pixels.
    const std::vector<shader::SurfaceTexel> tessellated = frame(TubeMethod::Tessellation, "tube tess");
    const Identity tess = compareVariants(tessellated, compute);
    EXPECT_GT(tess.covered, 100u) << tess.summary();
    EXPECT_LE(tess.fiber_mismatch, tess.covered / 100) << tess.summary();
    // Silhouettes within 1 px: a pixel only one of them covers has a
    // covered pixel of the other among its 8 neighbours.
    const auto hit = [&](const std::vector<shader::SurfaceTexel>& t, int x, int y) {
      return x >= 0 && y >= 0 && x < int(camera.width) && y < int(camera.height) &&
             t[size_t(y) * camera.width + size_t(x)].depth < 1.0f;
    };
    size_t far_off = 0;
    for (int y = 0; y < int(camera.height); ++y)
      for (int x = 0; x < int(camera.width); ++x) {
        const bool a = hit(tessellated, x, y), b = hit(compute, x, y);
        if (a == b) continue;
        const std::vector<shader::SurfaceTexel>& other = a ? compute : tessellated;
        bool near = false;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) near |= hit(other, x + dx, y + dy);
        far_off += !near;
      }
    EXPECT_EQ(far_off, 0u) << tess.summary();
    expectSameTexels(compareVariants(frame(TubeMethod::Compute, "tube raycast"), compute), "compute again");
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
}

// 300 short tubes piled in the same few tiles (the compute test's scene),
// the compute caster's lists held to 64 items, so its tiles overflow and
// test every sub-segment; the boxes need no lists.
TEST_F(GpuTubeRaster, fragmentAndComputeVariantsAgreeWhereTileListsOverflow) {
  Tractogram t;
  for (int i = 0; i < 300; ++i) {
    const float a = float(i) * 0.02f, z = float(i) * 0.008f;
    const float xyz[] = {-2.0f * std::cos(a), -2.0f * std::sin(a), z, 0.0f, 0.3f * std::sin(3.0f * a), z,
                         2.0f * std::cos(a),  2.0f * std::sin(a),  z};
    t.addStreamline(xyz, 3);
  }
  TubeBuildOptions o;
  o.radius.radius = 0.1f;
  const TubeModel model = buildTubes(t, o);
  ASSERT_GT(model.subSegmentCount(), size_t(64));
  const Camera camera = fitCamera(tractogramBounds(t), {0.2, -0.3, 1}, {0, 1, 0}, 48, 48);
  FrameStats compute_stats;
  const auto small_lists = [](const GpuTubes* tubes) {
    return tubeRaycastStage(tubes, TubeRaycastOptions{64 * sizeof(uint32_t)});
  };
  const std::vector<shader::SurfaceTexel> compute = cast(model, camera, small_lists, &compute_stats);
  ASSERT_GT(compute_stats.tube_tiles_overflowed, 0u);
  const std::vector<shader::SurfaceTexel> raster = cast(model, camera, tubeRasterRaycastStage);
  expectSameTexels(compareVariants(raster, compute), "overflowing tiles");
  const Agreement a =
      compareWithReference(raster, renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade), camera);
  EXPECT_GT(a.both, 300u) << a.summary();
  EXPECT_GE(a.agreement(), 0.98) << a.summary();
  EXPECT_LE(a.fiber_mismatch, a.both / 50) << a.summary();  // tubes overlapping within float depth
}

TEST_F(GpuTubeRaster, anEmptyModelDrawsNothing) {
  const TubeModel empty = buildTubes(Tractogram(), {});
  Camera camera;
  camera.eye = {0, 0, 30};
  camera.width = 32;
  camera.height = 24;
  FrameStats stats;
  const std::vector<shader::SurfaceTexel> surface = cast(empty, camera, tubeRasterRaycastStage, &stats);
  for (const shader::SurfaceTexel& t : surface) ASSERT_EQ(t.depth, 1.0f);
  for (const PassTiming& p : stats.passes) EXPECT_NE(p.name, "tube boxes");
  // And a model wholly behind the camera runs the passes and hits nothing.
  Tractogram t;
  const float xyz[] = {-1, 0, 40, 1, 0, 40, 2, 1, 41};
  t.addStreamline(xyz, 3);
  TubeBuildOptions o;
  o.radius.radius = 0.5f;
  const std::vector<shader::SurfaceTexel> behind = cast(buildTubes(t, o), camera, tubeRasterRaycastStage, &stats);
  ASSERT_FALSE(behind.empty());
  for (const shader::SurfaceTexel& s : behind) ASSERT_EQ(s.depth, 1.0f);
  bool timed_boxes = false;
  for (const PassTiming& p : stats.passes) timed_boxes |= p.name == "tube boxes";
  EXPECT_TRUE(timed_boxes);
}

// Opt-in (FIBSCOPE_TUBE_BENCH=1): the two variants side by side on the
// first 300 fibers of the 2,000-fiber phantom as tubes of 0.3 mm
// (resampled within radius / 20, as the command line does), 800 x 600,
// camera fitted to the phantom (from -y); GPU time of each variant's
// passes and the wall time of the frame (setup + tubes, submitted and
// waited for), the third of three frames.
TEST_F(GpuTubeRaster, benchComputeAgainstFragmentVariant) {
  const char* env = std::getenv("FIBSCOPE_TUBE_BENCH");
  if (!env || std::string(env) != "1") GTEST_SKIP() << "set FIBSCOPE_TUBE_BENCH=1 to run the benchmark";
  PhantomOptions po;
  po.streamlines = 2000;
  po.threads = 1;
  const Tractogram phantom = readAllStreamlines(*openPhantom(po));
  Tractogram selected;
  for (size_t f = 0; f < 300; ++f) selected.addStreamline(phantom.point(phantom.offsets[f]), phantom.pointsIn(f));
  TubeBuildOptions o;
  o.radius.radius = 0.3f;
  o.resample_tolerance = 0.3f / 20.0f;
  const TubeModel model = buildTubes(selected, o);
  const Camera camera = fitCamera(tractogramBounds(phantom), {0, -1, 0}, {0, 0, 1}, 800, 600);
  GpuTubes tubes = uploadTubes(context(), model);
  std::vector<shader::SurfaceTexel> images[2];
  try {
    const StageMaker makers[2] = {computeCaster, tubeRasterRaycastStage};
    const char* names[2] = {"compute", "fragment"};
    for (int v = 0; v < 2; ++v) {
      FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, makers[v](&tubes)});
      FrameStats stats;
      double wall_ms = 0;
      for (int frame = 0; frame < 3; ++frame) {
        const auto start = std::chrono::steady_clock::now();
        stats = renderer.render(camera, RenderSettings(), GpuScene());
        wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      }
      double total = 0;
      std::string passes;
      for (const PassTiming& p : stats.passes)
        if (p.name.rfind("tube", 0) == 0) {
          total += p.ms;
          passes += " " + p.name + " " + std::to_string(p.ms) + " ms;";
        }
      images[v] = downloadSurface(context(), renderer.targets());
      size_t covered = 0;
      for (const shader::SurfaceTexel& t : images[v]) covered += t.depth < 1.0f;
      std::printf("tube bench %s: %zu segments, %zu px covered, frame %.1f ms wall, tube passes %.1f ms:%s\n", names[v],
                  model.segments.size(), covered, wall_ms, total, passes.c_str());
    }
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
  const Identity id = compareVariants(images[1], images[0]);
  std::printf("tube bench: fragment against compute: %s\n", id.summary().c_str());
}

}  // namespace
}  // namespace fibscope
