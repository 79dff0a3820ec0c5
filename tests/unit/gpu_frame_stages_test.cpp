// The frame as a list of stages (render/gpu/frame_stage.h): the timer is
// sized from the list (a frame of 40 passes times every one), a stage is
// one line in the list, and the surface target: analytic spheres drawn
// with the lines by every pipeline occlude them and are occluded by them
// as the CPU reference of both (reference_raster.h) says, and picking
// returns a sphere's id. Validation layers on.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/pick.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

// A stage of `passes` timed passes, each a small fill.
class ManyPassesStage final : public FrameStage {
 public:
  ManyPassesStage(const gpu::VulkanContext& context, uint32_t passes)
      : passes_(passes), scratch_(gpu::createBuffer(context, 256, gpu::MemoryUse::DeviceLocal)) {}
  void destroy(const gpu::VulkanContext& context) override { gpu::destroyBuffer(context, scratch_); }
  uint32_t maxPasses() const override { return passes_; }
  bool runs(const FrameContext&) const override { return true; }
  void record(FrameContext& frame) override {
    for (uint32_t i = 0; i < passes_; ++i) {
      // Each fill before the next (synchronisation validation checks it).
      const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                   VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
      gpu::PassScope pass(frame.cmd, frame.timer, "extra " + std::to_string(i), after);
      vkCmdFillBuffer(frame.cmd, scratch_.buffer, 0, VK_WHOLE_SIZE, i);
    }
  }

 private:
  uint32_t passes_;
  gpu::Buffer scratch_;
};

// Straight parallel lines along x in the plane z = 0 (y from -12 to 12 mm
// every 1.5 mm, 0.25 mm steps), seen from +z.
Tractogram lineGrid() {
  Tractogram t;
  std::vector<float> xyz;
  for (int row = 0; row <= 16; ++row) {
    xyz.clear();
    for (int i = 0; i <= 240; ++i) {
      xyz.push_back(-30.0f + 0.25f * float(i));
      xyz.push_back(-12.0f + 1.5f * float(row));
      xyz.push_back(0.0f);
    }
    t.addStreamline(xyz.data(), xyz.size() / 3);
  }
  return t;
}

constexpr uint32_t kWidth = 160, kHeight = 120;
constexpr uint32_t kSphereIds = 1000;

Camera topCamera() {
  Camera c;
  c.eye = {0, 0, 120};
  c.target = {0, 0, 0};
  c.up = {0, 1, 0};
  c.width = kWidth;
  c.height = kHeight;
  return c;
}

// In front of the lines, behind them, and cut by them.
std::vector<ReferenceSphere> testSpheres() {
  return {{{0, 0, 6}, 5, kSphereIds}, {{18, 0, -6}, 5, kSphereIds + 1}, {{-18, 0, 0}, 5, kSphereIds + 2}};
}

std::vector<shader::SurfaceSphere> gpuSpheres(const std::vector<ReferenceSphere>& spheres) {
  std::vector<shader::SurfaceSphere> out;
  for (const ReferenceSphere& s : spheres) {
    shader::SurfaceSphere g{};
    g.center_radius = {float(s.center[0]), float(s.center[1]), float(s.center[2]), float(s.radius)};
    g.id = s.id;
    out.push_back(g);
  }
  return out;
}

// The pixel whose centre a world point projects nearest to.
std::pair<uint32_t, uint32_t> project(const Camera& camera, const std::array<double, 3>& p) {
  const std::array<double, 16> vp = viewProjectionD(camera);
  const double x = vp[0] * p[0] + vp[4] * p[1] + vp[8] * p[2] + vp[12];
  const double y = vp[1] * p[0] + vp[5] * p[1] + vp[9] * p[2] + vp[13];
  const double w = vp[3] * p[0] + vp[7] * p[1] + vp[11] * p[2] + vp[15];
  return {uint32_t((x / w + 1) * camera.width / 2), uint32_t((y / w + 1) * camera.height / 2)};
}

class GpuFrameStages : public test::GpuTest {};

TEST_F(GpuFrameStages, theTimerTakesEveryPassOfAFrameOfFortyPasses) {
  const Tractogram fibers = test::renderPhantom(60, 3);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  FrameStageList stages = standardFrameStages();
  stages.push_back([](const gpu::VulkanContext& c) { return std::make_unique<ManyPassesStage>(c, 24); });
  FrameRenderer renderer(context(), 64, 48, stages);
  EXPECT_GE(renderer.passCapacity(), 40u);
  RenderSettings settings;
  settings.culling = CullingMode::TwoPhase;
  settings.ssao = true;
  settings.fxaa = true;
  GpuScene scene(&upload.dataset);
  scene.spheres = gpuSpheres({{{0, 0, 0}, 3, 7}});
  const Camera camera = orbitCamera(tractogramBounds(fibers), 30, 10, 64, 48);
  const FrameStats stats = renderer.render(camera, settings, scene);
  std::vector<std::string> names;
  for (const PassTiming& p : stats.passes) {
    names.push_back(p.name);
    EXPECT_TRUE(std::isfinite(p.ms) && p.ms >= 0) << p.name;
  }
  const std::vector<std::string> first = {"clear", "fiblet bounds", "cull 1", "raster 1", "depth pyramid", "cull 2",
                                          "raster 2", "resolve", "spheres", "surface merge", "tiles", "ssao",
                                          "ssao blur", "shade", "fxaa"};
  ASSERT_EQ(names.size(), first.size() + 24);
  for (size_t i = 0; i < first.size(); ++i) EXPECT_EQ(names[i], first[i]);
  EXPECT_EQ(names.back(), "extra 23");
  // The second frame has its spheres already: one pass fewer.
  EXPECT_EQ(renderer.render(camera, settings, scene).passes.size(), first.size() + 23);
}

TEST_F(GpuFrameStages, framesWithoutSurfacesMakeNoSurfaceTarget) {
  const Tractogram fibers = lineGrid();
  const TractogramUpload upload = uploadTractogram(context(), fibers, "grid");
  FrameRenderer renderer(context(), kWidth, kHeight);
  const FrameStats stats = renderer.render(topCamera(), RenderSettings{}, GpuScene(&upload.dataset));
  EXPECT_FALSE(renderer.targets().surface.buffer);
  for (const PassTiming& p : stats.passes) EXPECT_NE(p.name, "surface merge");
}

// Where each source wins in the GPU frame and in the reference: lines
// (fiber < kSphereIds) and spheres.
struct SourceMasks {
  std::vector<uint8_t> lines, spheres;
};
SourceMasks masks(const std::vector<uint32_t>& fiber) {
  SourceMasks m;
  for (uint32_t f : fiber) {
    m.lines.push_back(f != shader::kNoFiberId && f < kSphereIds ? 1 : 0);
    m.spheres.push_back(f != shader::kNoFiberId && f >= kSphereIds ? 1 : 0);
  }
  return m;
}

TEST_F(GpuFrameStages, spheresAndLinesOccludeEachOtherBothWaysAsTheReferenceInEveryPipeline) {
  const Tractogram fibers = lineGrid();
  const TractogramUpload upload = uploadTractogram(context(), fibers, "grid");
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers, "grid");
  const Camera camera = topCamera();
  const std::vector<ReferenceSphere> spheres = testSpheres();
  ReferenceFrame reference = rasterizeReference(fibers, camera, 2.0f);
  rasterizeReferenceSpheres(reference, spheres, camera);
  const SourceMasks want = masks(reference.fiber);
  // The reference itself shows both ways: lines hidden by the front sphere,
  // lines over the sphere behind them, and both in the cut one.
  const auto [ax, ay] = project(camera, spheres[0].center);
  EXPECT_EQ(reference.fiber[reference.index(ax, ay)], kSphereIds);
  size_t lines_over_back_sphere = 0, back_sphere = 0;
  for (uint32_t y = 0; y < kHeight; ++y)
    for (uint32_t x = 0; x < kWidth; ++x) {
      const uint32_t f = reference.fiber[reference.index(x, y)];
      back_sphere += f == kSphereIds + 1;
      // Pixels in the back sphere's disk (|x - its centre| < 4 mm) drawn by lines.
      const auto [bx, by] = project(camera, spheres[1].center);
      lines_over_back_sphere += f < kSphereIds && std::abs(int(x) - int(bx)) < 10 && std::abs(int(y) - int(by)) < 10;
    }
  ASSERT_GT(back_sphere, 50u);
  ASSERT_GT(lines_over_back_sphere, 20u);

  FrameRenderer renderer(context(), kWidth, kHeight);
  GpuScene scene(&upload.dataset, &raw);
  scene.spheres = gpuSpheres(spheres);
  for (const RenderPipeline pipeline : {RenderPipeline::Compute, RenderPipeline::RawCompute, RenderPipeline::Lines}) {
    SCOPED_TRACE(std::string(renderPipelineName(pipeline)));
    RenderSettings settings;
    settings.pipeline = pipeline;
    settings.line_width_px = 2.0f;
    renderer.render(camera, settings, scene);
    const auto texels = downloadGBuffer(context(), renderer.targets());
    std::vector<uint32_t> fiber;
    for (const shader::GBufferTexel& t : texels) fiber.push_back(t.fiber);
    const SourceMasks got = masks(fiber);
    const CoverageComparison s = compareCoverage(got.spheres, want.spheres, kWidth, kHeight);
    EXPECT_GE(s.agreement, 0.98) << "spheres: " << s.summary();
    EXPECT_LE(s.maxDistance(), 1.0) << "spheres: " << s.summary();
    // The device's line rasterisation is not the reference's capsule rule
    // (lines_pass.h): only the compute pipelines are held to it.
    if (pipeline != RenderPipeline::Lines) {
      const CoverageComparison l = compareCoverage(got.lines, want.lines, kWidth, kHeight);
      EXPECT_GE(l.agreement, 0.98) << "lines: " << l.summary();
      EXPECT_LE(l.maxDistance(), 1.0) << "lines: " << l.summary();
    }
    // Surface pixels carry their source; lines pixels do not.
    for (size_t i = 0; i < texels.size(); ++i) {
      if (got.spheres[i]) {
        EXPECT_EQ(texels[i].segment, shader::kGBufferSurface | shader::kSurfaceSourceSphere);
      }
      if (got.lines[i]) {
        EXPECT_EQ(texels[i].segment & shader::kGBufferSurface, 0u);
      }
    }
    const PickResult pick = pickFiber(context(), renderer.targets(), ax, ay);
    EXPECT_TRUE(pick.hit);
    EXPECT_TRUE(pick.surface);
    EXPECT_EQ(pick.fiber, kSphereIds);
    EXPECT_EQ(pick.source, shader::kSurfaceSourceSphere);
  }
}

TEST_F(GpuFrameStages, sphereDepthsAndNormalsAreTheReferences) {
  const Camera camera = topCamera();
  const std::vector<ReferenceSphere> spheres = testSpheres();
  ReferenceFrame reference(kWidth, kHeight);
  rasterizeReferenceSpheres(reference, spheres, camera);
  // The surface target holds what the spheres drew whatever the lines.
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), lineGrid(), "grid");
  FrameRenderer renderer(context(), kWidth, kHeight);
  GpuScene scene(nullptr, &raw);
  scene.spheres = gpuSpheres(spheres);
  RenderSettings settings;
  settings.pipeline = RenderPipeline::RawCompute;
  renderer.render(camera, settings, scene);
  const auto surface = downloadSurface(context(), renderer.targets());
  ASSERT_EQ(surface.size(), size_t(kWidth) * kHeight);
  size_t compared = 0;
  for (size_t i = 0; i < surface.size(); ++i) {
    if (reference.fiber[i] == kNoFiber || surface[i].depth >= 1.0f) continue;
    // Silhouette pixels may differ by the float rounding of the ray: only
    // those both frames hit are compared.
    ++compared;
    ASSERT_EQ(surface[i].fiber, reference.fiber[i]) << "pixel " << i;
    EXPECT_NEAR(surface[i].depth, reference.depth[i], 2e-6) << "pixel " << i;
    const std::array<float, 3> n = test::unpackTangent(surface[i].normal);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], reference.tangent[i][k], 2e-3) << "pixel " << i;
  }
  EXPECT_GT(compared, 500u);
}

}  // namespace
}  // namespace fibscope
