// The compute ray casting of spline tubes (src/tubes/gpu, tube_bin.comp,
// tube_raycast.comp) against the CPU reference of the same intersection
// (src/tubes/tube_intersect.h, itself tested against the brute-force sphere
// sweep): hit/miss, depth, fiber, normal and position along the fiber per
// pixel in the surface target, on curved test tubes from three views, and
// with tiles whose lists overflow. Validation layers on.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
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
  std::vector<shader::SurfaceTexel> castOnGpu(const TubeModel& model, const Camera& camera) {
    GpuTubes tubes = uploadTubes(context(), model);
    std::vector<shader::SurfaceTexel> surface;
    try {
      // The compute pipeline's frame over no datasets: no geometry stage.
      FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, tubeRaycastStage(&tubes)});
      renderer.render(camera, RenderSettings(), GpuScene());
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
    a.max_normal_error = std::max(a.max_normal_error, double(glm::distance(glm::vec3(g[0], g[1], g[2]), ref.normal[i])));
    a.max_position_error = std::max(a.max_position_error, double(std::fabs(gpu[i].position - ref.position[i])));
  }
  return a;
}

TEST_F(GpuTubeRaycast, computeRayCastingMatchesTheCpuReferenceOnCurvedTubes) {
  for (const test::TubeScene& scene : test::tubeScenes()) {
    const TubeModel model = buildTubes(scene.tractogram, scene.options);
    for (const Camera& camera : test::tubeSceneCameras(scene, 120, 90)) {
      const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
      const Agreement a = compare(castOnGpu(model, camera), ref, camera);
      const std::string what = scene.name + " from (" + std::to_string(camera.eye[0]) + ", " +
                               std::to_string(camera.eye[1]) + ", " + std::to_string(camera.eye[2]) + "): " +
                               a.summary();
      EXPECT_GT(a.both, 250u) << what;
      EXPECT_GE(a.agreement(), 0.98) << what;
      EXPECT_EQ(a.fiber_mismatch, 0u) << what;
      EXPECT_LE(a.max_depth_mm, 1e-4 * scene.min_radius) << what;
      EXPECT_LE(a.max_normal_error, 1e-2) << what;  // measured: 4e-3 (t from 10 bisections)
      EXPECT_LE(a.max_position_error, 5e-3) << what;
    }
  }
}

// 120 short tubes piled in the same few tiles: up to 480 sub-segments a tile,
// past kTubeTileCapacity, so those tiles test every sub-segment.
TEST_F(GpuTubeRaycast, tilesWhoseListsOverflowStillDrawEveryTube) {
  Tractogram t;
  for (int i = 0; i < 120; ++i) {
    const float a = float(i) * 0.05f, z = float(i) * 0.02f;
    const float xyz[] = {-2.0f * std::cos(a), -2.0f * std::sin(a), z, 0.0f, 0.3f * std::sin(3.0f * a), z,
                         2.0f * std::cos(a), 2.0f * std::sin(a), z};
    t.addStreamline(xyz, 3);
  }
  TubeBuildOptions o;
  o.radius.radius = 0.1f;
  const TubeModel model = buildTubes(t, o);
  ASSERT_GT(model.subSegmentCount(), size_t(shader::kTubeTileCapacity));
  Bounds b = tractogramBounds(t);
  const Camera camera = fitCamera(b, {0.2, -0.3, 1}, {0, 1, 0}, 48, 48);
  const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
  const Agreement a = compare(castOnGpu(model, camera), ref, camera);
  EXPECT_GT(a.both, 300u) << a.summary();
  EXPECT_GE(a.agreement(), 0.98) << a.summary();
  EXPECT_LE(a.fiber_mismatch, a.both / 50) << a.summary();  // tubes overlapping within float depth
}

TEST_F(GpuTubeRaycast, aModelWithoutSegmentsDrawsNothingAndUploadsNothing) {
  Tractogram t;
  const float one[] = {0, 0, 0};
  t.addStreamline(one, 1);
  const TubeModel model = buildTubes(t, {});
  GpuTubes tubes = uploadTubes(context(), model);
  EXPECT_EQ(tubes.segment_count, 0u);
  EXPECT_EQ(tubes.nodes.buffer, VK_NULL_HANDLE);
  destroyTubes(context(), tubes);
}

}  // namespace
}  // namespace fibscope
