// Cuts on the spline tubes (issue 15 item 4; shaders/glsl/surface_cuts.glsl)
// and the SVO streamtubes (issue 16 item 3): with a clip plane through a
// tube, every method (compute and fragment ray casting, tessellation, the
// straight and curved octree) draws the tube only on the kept side, up to the
// plane within a pixel, and the same tube without the plane on both
// sides. The kept side is checked on the world point each covered pixel's
// depth puts on the pixel's ray, an independent reconstruction.
// Validation layers on; 96 x 48 frames.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "tube_test_scenes.h"
#include "svo/gpu/gpu_svo.h"
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/tube_intersect.h"

namespace fibscope {
namespace {

// One straight fiber along x (a tube of radius 1.5 mm), seen from +z.
Tractogram straightFiber() {
  Tractogram t;
  std::vector<float> xyz;
  for (int i = 0; i <= 20; ++i) xyz.insert(xyz.end(), {-10.0f + float(i), 0.0f, 0.0f});
  t.addStreamline(xyz.data(), 21);
  return t;
}
TubeModel straightTube() {
  TubeBuildOptions o;
  o.radius.radius = 1.5f;
  return buildTubes(straightFiber(), o);
}

constexpr double kPlaneX = 2.0;  // the plane keeps x >= 2: n = (1, 0, 0), d = -2

// `whole` and `cut` (the same frame without and with the plane): the tube
// covers both sides without it, only the kept side with it (each covered
// pixel's depth on its ray gives a world point with x >= the plane), and
// nothing well inside the kept side is lost.
void expectCutAtThePlane(const Camera& camera, const std::vector<shader::SurfaceTexel>& whole,
                         const std::vector<shader::SurfaceTexel>& cut) {
  const double n = camera.near_mm, f = camera.far_mm;
  const std::array<double, 16> view = viewMatrixD(camera);
  const glm::dvec3 forward(-view[2], -view[6], -view[10]);
  size_t whole_left = 0, whole_right = 0, cut_right = 0, wrong_side = 0, lost = 0;
  double min_x = 1e9;
  for (uint32_t py = 0; py < camera.height; ++py)
    for (uint32_t px = 0; px < camera.width; ++px) {
      const size_t i = size_t(py) * camera.width + px;
      glm::dvec3 origin, dir;
      tubePixelRay(camera, px, py, origin, dir);
      // The pixel's x at the tube's axis plane z = 0 (the ray from +z).
      const double axis_x = origin.x + dir.x * (-origin.z / dir.z);
      if (whole[i].depth < 1.0f) (axis_x < kPlaneX ? whole_left : whole_right) += 1;
      if (!(cut[i].depth < 1.0f)) {
        lost += whole[i].depth < 1.0f && axis_x > kPlaneX + 1.0;
        continue;
      }
      ++cut_right;
      const double z = n * f / (f - double(cut[i].depth) * (f - n));
      const glm::dvec3 hit = origin + dir * (z / glm::dot(dir, forward));
      min_x = std::min(min_x, hit.x);
      wrong_side += hit.x < kPlaneX - 0.05;  // tessellation's faceting stays far below 0.05 mm here
    }
  EXPECT_GT(whole_left, 100u);  // 188 and 128 pixels at this size
  EXPECT_GT(whole_right, 100u);
  EXPECT_GT(cut_right, whole_right / 2);
  EXPECT_EQ(wrong_side, 0u) << "nearest hit x " << min_x;
  EXPECT_EQ(lost, 0u);
}

class GpuTubeCuts : public test::GpuTest {
 protected:
  // The surface target of `renderer`'s frame without and with the plane.
  void expectCut(FrameRenderer& renderer, const Camera& camera, RenderSettings settings) {
    renderer.render(camera, settings, GpuScene());
    const std::vector<shader::SurfaceTexel> whole = downloadSurface(context(), renderer.targets());
    settings.clip_planes = {{1.0, 0.0, 0.0, -kPlaneX}};
    renderer.render(camera, settings, GpuScene());
    expectCutAtThePlane(camera, whole, downloadSurface(context(), renderer.targets()));
  }
};

TEST_F(GpuTubeCuts, aClipPlaneCutsTheTubesOfEveryMethodAtThePlane) {
  const TubeModel model = straightTube();
  const Camera camera = fitCamera(tractogramBounds(straightFiber()), {0, 0, 1}, {0, 1, 0}, 96, 48);
  GpuTubes tubes = uploadTubes(context(), model);
  try {
    FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, tubeStage(&tubes)});
    for (const TubeMethod method : {TubeMethod::Compute, TubeMethod::Raycast, TubeMethod::Tessellation}) {
      SCOPED_TRACE(std::string(tubeMethodName(method)));
      RenderSettings settings;
      settings.tube_method = method;
      expectCut(renderer, camera, settings);
    }
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
}

// The SVO's ray is cut to the planes' stretch before the walk (svo_trace.comp).
TEST_F(GpuTubeCuts, aClipPlaneCutsTheSvoTubesAtThePlane) {
  const TubeModel model = straightTube();
  const Camera camera = fitCamera(tractogramBounds(straightFiber()), {0, 0, 1}, {0, 1, 0}, 96, 48);
  GpuTubes tubes = uploadTubes(context(), model);
  GpuSvo svo;
  try {
    for (const bool curved : {false, true}) {
      SCOPED_TRACE(curved ? "curved" : "straight");
      destroySvo(context(), svo);
      svo = uploadSvo(context(), buildSvoGpu(context(), model, tubes, chooseSvoGrid(model, 0.5f, curved)));
      FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, svoTraceStage(&svo, &tubes)});
      expectCut(renderer, camera, RenderSettings());
    }
  } catch (...) {
    destroySvo(context(), svo);
    destroyTubes(context(), tubes);
    throw;
  }
  destroySvo(context(), svo);
  destroyTubes(context(), tubes);
}

}  // namespace
}  // namespace fibscope
