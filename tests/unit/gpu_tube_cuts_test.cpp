// Cuts on the spline tubes (issue 15 item 4; shaders/glsl/surface_cuts.glsl):
// with a clip plane through a tube, every method (compute and fragment ray
// casting, tessellation) draws the tube only on the kept side, up to the
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
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/tube_intersect.h"

namespace fibscope {
namespace {

class GpuTubeCuts : public test::GpuTest {};

TEST_F(GpuTubeCuts, aClipPlaneCutsTheTubesOfEveryMethodAtThePlane) {
  // One straight tube along x, radius 1.5 mm, seen from +z.
  Tractogram t;
  std::vector<float> xyz;
  for (int i = 0; i <= 20; ++i) xyz.insert(xyz.end(), {-10.0f + float(i), 0.0f, 0.0f});
  t.addStreamline(xyz.data(), 21);
  TubeBuildOptions o;
  o.radius.radius = 1.5f;
  const TubeModel model = buildTubes(t, o);
  const Camera camera = fitCamera(tractogramBounds(t), {0, 0, 1}, {0, 1, 0}, 96, 48);
  const double plane_x = 2.0;  // keeps x >= 2: n = (1, 0, 0), d = -2
  const double n = camera.near_mm, f = camera.far_mm;
  const std::array<double, 16> view = viewMatrixD(camera);
  const glm::dvec3 forward(-view[2], -view[6], -view[10]);
  GpuTubes tubes = uploadTubes(context(), model);
  try {
    FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, tubeStage(&tubes)});
    for (const TubeMethod method : {TubeMethod::Compute, TubeMethod::Raycast, TubeMethod::Tessellation}) {
      SCOPED_TRACE(std::string(tubeMethodName(method)));
      RenderSettings settings;
      settings.tube_method = method;
      renderer.render(camera, settings, GpuScene());
      const std::vector<shader::SurfaceTexel> whole = downloadSurface(context(), renderer.targets());
      settings.clip_planes = {{1.0, 0.0, 0.0, -plane_x}};
      renderer.render(camera, settings, GpuScene());
      const std::vector<shader::SurfaceTexel> cut = downloadSurface(context(), renderer.targets());
      size_t whole_left = 0, whole_right = 0, cut_right = 0, wrong_side = 0, lost = 0;
      double min_x = 1e9;
      for (uint32_t py = 0; py < camera.height; ++py)
        for (uint32_t px = 0; px < camera.width; ++px) {
          const size_t i = size_t(py) * camera.width + px;
          glm::dvec3 origin, dir;
          tubePixelRay(camera, px, py, origin, dir);
          // The pixel's x at the tube's axis plane z = 0 (the ray from +z).
          const double axis_x = origin.x + dir.x * (-origin.z / dir.z);
          if (whole[i].depth < 1.0f) (axis_x < plane_x ? whole_left : whole_right) += 1;
          if (!(cut[i].depth < 1.0f)) {
            // Well inside the kept side and covered before: lost.
            lost += whole[i].depth < 1.0f && axis_x > plane_x + 1.0;
            continue;
          }
          ++cut_right;
          const double z = n * f / (f - double(cut[i].depth) * (f - n));
          const glm::dvec3 hit = origin + dir * (z / glm::dot(dir, forward));
          min_x = std::min(min_x, hit.x);
          wrong_side += hit.x < plane_x - 0.05;  // tessellation's faceting stays far below 0.05 mm here
        }
      EXPECT_GT(whole_left, 100u);  // 188 and 128 pixels at this size
      EXPECT_GT(whole_right, 100u);
      EXPECT_GT(cut_right, whole_right / 2);
      EXPECT_EQ(wrong_side, 0u) << "nearest hit x " << min_x;
      EXPECT_EQ(lost, 0u);
    }
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
}

}  // namespace
}  // namespace fibscope
