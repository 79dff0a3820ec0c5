// Cuts drawn per pixel (render/clip_planes.h, shared/camera.h): clip planes
// and mrview's slab clip every pipeline's segments exactly at the planes.
// The compute and raw-compute pipelines agree with the CPU reference
// rasteriser clipping the same planes in world space (>= 98 % of covered
// pixels, none more than 1 px away), the lines baseline draws nothing on
// the cut side, and two-phase culling on versus off gives the same frame
// with cuts, across a 60 degree jump and with a slab that moves with the
// view. Validation layers on (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <array>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/clip_planes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "select/cut_mesh.h"

namespace fibscope {
namespace {

using test::gbufferMask;

constexpr uint32_t kSize = 160;

struct CutCase {
  const char* name;
  std::vector<PlaneEq> planes;
  float slab_mm = 0;
  std::optional<PlaneEq> slab_plane;
};

class GpuCuts : public test::GpuTest {
 public:
  // Pixels whose visibility keys differ between two renderers' frames.
  size_t keysDiffering(const FrameRenderer& a, const FrameRenderer& b) {
    const auto ka = downloadVisibility(context(), a.targets()), kb = downloadVisibility(context(), b.targets());
    size_t differ = 0;
    for (size_t i = 0; i < ka.size(); ++i) differ += ka[i] != kb[i];
    return differ;
  }

 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    // The named bundles: the cut meshes sit where they cut visible fibers
    // (the whole-brain mix hides the centre behind the fibers in front).
    fibers_ = test::renderPhantom(400, 5, true);
    bounds_ = tractogramBounds(fibers_);
    for (int k = 0; k < 3; ++k) centre_[k] = 0.5 * (bounds_.min[k] + bounds_.max[k]);
    upload_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers_, "phantom"));
  }
  void TearDown() override {
    upload_.reset();
    test::GpuTest::TearDown();
  }
  std::vector<CutCase> cases() const {
    const std::array<double, 3> c = centre_;
    return {
        {"oblique plane", {planeThrough(c, {0.4, -0.3, 0.87})}},
        {"two planes, a wedge", {planeThrough(c, {1, 0, 0}), planeThrough({c[0], c[1] + 10, c[2]}, {0.2, -1, 0.3})}},
        {"axial slab of 12 mm", {}, 12.0f, planeThrough({c[0], c[1], c[2] + 5}, {0, 0, 1})},
        {"focal slab and a plane", {planeThrough(c, {0, 1, 0})}, 25.0f, std::nullopt},
    };
  }
  static RenderSettings cutSettings(const CutCase& cut, CullingMode culling, RenderPipeline pipeline, float width) {
    RenderSettings s;
    s.pipeline = pipeline;
    s.culling = culling;
    s.lod_pixels = 0;
    s.ssao = false;
    s.line_width_px = width;
    s.clip_planes = cut.planes;
    s.slab_mm = cut.slab_mm;
    s.slab_plane = cut.slab_plane;
    return s;
  }

  Tractogram fibers_;
  Bounds bounds_;
  std::array<double, 3> centre_{};
  std::unique_ptr<TractogramUpload> upload_;
};

TEST_F(GpuCuts, computeAndRawComputeClipAsTheReferenceDoes) {
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
  FrameRenderer renderer(context(), kSize, kSize);
  const Camera cameras[] = {orbitCamera(bounds_, 30, 20, kSize, kSize, 1.0),
                            standardView(bounds_, StandardView::Coronal, kSize, kSize)};
  for (const CutCase& cut : cases()) {
    for (const Camera& camera : cameras) {
      for (float width : {1.0f, 2.5f}) {
        const std::vector<PlaneEq> planes = frameClipPlanes(cutSettings(cut, CullingMode::None,
                                                                        RenderPipeline::Compute, width), camera);
        const ReferenceFrame whole = rasterizeReference(fibers_, camera, width);
        const ReferenceFrame reference = rasterizeReference(fibers_, camera, width, planes);
        ASSERT_GT(reference.coveredPixels(), kSize * kSize / 100) << cut.name << ": something is left";
        ASSERT_LT(reference.coveredPixels(), whole.coveredPixels() * 9 / 10) << cut.name << ": the cut cuts";
        for (RenderPipeline pipeline : {RenderPipeline::Compute, RenderPipeline::RawCompute}) {
          SCOPED_TRACE(std::string(cut.name) + (pipeline == RenderPipeline::Compute ? ", compute" : ", raw-compute") +
                       ", width " + std::to_string(width));
          renderer.render(camera, cutSettings(cut, CullingMode::None, pipeline, width),
                          GpuScene{&upload_->dataset, &raw});
          const auto texels = downloadGBuffer(context(), renderer.targets());
          const CoverageComparison c = compareCoverage(gbufferMask(texels), reference.coverageMask(), kSize, kSize);
          EXPECT_GE(c.agreement, 0.98) << c.summary();
          EXPECT_LE(c.maxDistance(), 1.0) << c.summary();
        }
      }
    }
  }
}

TEST_F(GpuCuts, linesDrawNothingOnTheCutSide) {
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
  FrameRenderer renderer(context(), kSize, kSize);
  const Camera camera = orbitCamera(bounds_, 30, 20, kSize, kSize, 1.0);
  const std::array<double, 16> vp = viewProjectionD(camera);
  const glm::dmat4 inverse = glm::inverse(glm::make_mat4(vp.data()));
  for (const CutCase& cut : cases()) {
    SCOPED_TRACE(cut.name);
    const RenderSettings settings = cutSettings(cut, CullingMode::None, RenderPipeline::Lines, 1.0f);
    const std::vector<PlaneEq> planes = frameClipPlanes(settings, camera);
    renderer.render(camera, settings, GpuScene{nullptr, &raw});
    const auto texels = downloadGBuffer(context(), renderer.targets());
    const ReferenceFrame reference = rasterizeReference(fibers_, camera, 1.0f, planes);
    size_t covered = 0, outside = 0;
    for (uint32_t y = 0; y < kSize; ++y)
      for (uint32_t x = 0; x < kSize; ++x) {
        const shader::GBufferTexel& t = texels[size_t(y) * kSize + x];
        if (t.fiber == shader::kNoFiberId) continue;
        ++covered;
        // The pixel's point on the line, back in world space: on the kept
        // side of every plane, to within the pixel's footprint (a line
        // pixel's centre lies up to half a pixel across the clipped end).
        const glm::dvec4 ndc((x + 0.5) / kSize * 2 - 1, (y + 0.5) / kSize * 2 - 1, t.depth, 1);
        glm::dvec4 w = inverse * ndc;
        w /= w.w;
        const double px_mm = 2.0 * std::tan(glm::radians(camera.fov_y_deg) / 2) *
                             glm::length(glm::dvec3(w) - glm::dvec3(camera.eye[0], camera.eye[1], camera.eye[2])) /
                             kSize;
        for (const PlaneEq& q : planes)
          if (q[0] * w.x + q[1] * w.y + q[2] * w.z + q[3] < -2.0 * px_mm) {
            ++outside;
            break;
          }
      }
    EXPECT_EQ(outside, 0u) << "of " << covered;
    EXPECT_NEAR(double(covered), double(reference.coveredPixels()), 0.25 * double(reference.coveredPixels()));
  }
}

TEST_F(GpuCuts, twoPhaseCullingWithCutsGivesTheUnculledFrame) {
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  std::vector<double> azimuths;
  for (int i = 0; i < 5; ++i) azimuths.push_back(30 + 1.5 * i);
  azimuths.push_back(30 + 1.5 * 4 + 60);  // a 60 degree jump
  azimuths.push_back(30 + 1.5 * 5 + 60);
  for (const CutCase& cut : cases()) {
    uint64_t drawn = 0, total = 0;
    for (double az : azimuths) {
      SCOPED_TRACE(std::string(cut.name) + ", azimuth " + std::to_string(az));
      const Camera camera = orbitCamera(bounds_, az, 20, kSize, kSize, 0.8);
      reference.render(camera, cutSettings(cut, CullingMode::None, RenderPipeline::Compute, 2.0f),
                       GpuScene{&upload_->dataset});
      const FrameStats stats = culled.render(camera, cutSettings(cut, CullingMode::TwoPhase, RenderPipeline::Compute, 2.0f),
                                             GpuScene{&upload_->dataset});
      EXPECT_EQ(keysDiffering(reference, culled), 0u) << "visibility keys differ";
      drawn += stats.fiblets_drawn;
      total += stats.fiblets_total;
    }
    // The cut's planes cull fiblets wholly on their cut side too.
    EXPECT_LT(drawn, total) << cut.name;
  }
}

// The mesh cuts of the tests: a box around part of the phantom and a
// sphere (icosphere) through its middle, each inside and outside.
struct MeshCase {
  const char* name;
  TriangleMesh mesh;
  bool cull_inside;
};

std::vector<MeshCase> meshCases(const std::array<double, 3>& c, const Bounds& b) {
  const double ex = b.max[0] - b.min[0];
  BoxRegion box;
  box.min = {c[0] - 0.3 * ex, c[1] - 0.25 * ex, c[2] - 0.1 * ex};
  box.max = {c[0] + 0.1 * ex, c[1] + 0.3 * ex, c[2] + 0.35 * ex};
  const TriangleMesh sphere = makeSphereMesh(glm::vec3(c[0], c[1], c[2] + 0.1 * ex), float(0.25 * ex), 3);
  return {{"box, cull inside", makeBoxMesh(box), true},
          {"box, cull outside", makeBoxMesh(box), false},
          {"sphere, cull inside", sphere, true},
          {"sphere, cull outside", sphere, false}};
}

TEST_F(GpuCuts, meshCutsDiscardAsTheReferenceDoesInEveryPipeline) {
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
  FrameRenderer renderer(context(), kSize, kSize);
  const Camera cameras[] = {orbitCamera(bounds_, 30, 20, kSize, kSize, 1.0),
                            standardView(bounds_, StandardView::Axial, kSize, kSize)};
  for (const MeshCase& mc : meshCases(centre_, bounds_)) {
    const GpuCutMesh mesh = GpuCutMesh::upload(context(), mc.mesh, mc.name);
    for (const Camera& camera : cameras) {
      const ReferenceFrame whole = rasterizeReference(fibers_, camera, 2.0f);
      const ReferenceFrame reference =
          rasterizeReference(fibers_, camera, 2.0f, {}, {referenceMeshCut(mc.mesh, camera, mc.cull_inside)});
      ASSERT_GT(reference.coveredPixels(), kSize * kSize / 100) << mc.name << ": something is left";
      size_t changed = 0;  // pixels where the cut shows another fiber or none
      for (size_t i = 0; i < whole.fiber.size(); ++i) changed += whole.fiber[i] != reference.fiber[i];
      ASSERT_GT(changed, whole.coveredPixels() / 20) << mc.name << ": the cut cuts";
      for (RenderPipeline pipeline : {RenderPipeline::Compute, RenderPipeline::RawCompute, RenderPipeline::Lines}) {
        SCOPED_TRACE(std::string(mc.name) + ", " + std::string(renderPipelineName(pipeline)));
        RenderSettings settings;
        settings.pipeline = pipeline;
        settings.culling = CullingMode::None;
        settings.ssao = false;
        settings.line_width_px = 2.0f;
        GpuScene scene{&upload_->dataset, &raw};
        scene.cut_meshes = {{&mesh, mc.cull_inside}};
        renderer.render(camera, settings, scene);
        const auto texels = downloadGBuffer(context(), renderer.targets());
        const CoverageComparison c = compareCoverage(gbufferMask(texels), reference.coverageMask(), kSize, kSize);
        // The lines baseline rasterises by the hardware's line rule, not the
        // reference's capsules: looser, as in the baselines' own test.
        EXPECT_GE(c.agreement, pipeline == RenderPipeline::Lines ? 0.8 : 0.98) << c.summary();
        std::printf("%s, %s: %s\n", mc.name, std::string(renderPipelineName(pipeline)).c_str(), c.summary().c_str());
        if (pipeline != RenderPipeline::Lines) EXPECT_LE(c.maxDistance(), 1.0) << c.summary();
      }
    }
  }
}

TEST_F(GpuCuts, twoPhaseCullingWithAMeshCutGivesTheUnculledFrame) {
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  for (const MeshCase& mc : meshCases(centre_, bounds_)) {
    const GpuCutMesh mesh = GpuCutMesh::upload(context(), mc.mesh, mc.name);
    GpuScene scene{&upload_->dataset};
    scene.cut_meshes = {{&mesh, mc.cull_inside}};
    uint64_t drawn = 0, total = 0;
    for (double az : {30.0, 31.5, 33.0, 93.0, 94.5}) {  // a 60 degree jump after three frames
      SCOPED_TRACE(std::string(mc.name) + ", azimuth " + std::to_string(az));
      const Camera camera = orbitCamera(bounds_, az, 20, kSize, kSize, 0.8);
      RenderSettings none, two_phase;
      none.culling = CullingMode::None;
      two_phase.culling = CullingMode::TwoPhase;
      none.ssao = two_phase.ssao = false;
      two_phase.lod_pixels = 0;
      none.line_width_px = two_phase.line_width_px = 2.0f;
      reference.render(camera, none, scene);
      const FrameStats stats = culled.render(camera, two_phase, scene);
      EXPECT_EQ(keysDiffering(reference, culled), 0u) << "visibility keys differ";
      drawn += stats.fiblets_drawn;
      total += stats.fiblets_total;
    }
    std::printf("%s: two-phase drew %.3f of the fiblets\n", mc.name, double(drawn) / double(total));
  }
}

}  // namespace
}  // namespace fibscope
