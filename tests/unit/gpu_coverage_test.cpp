// The coverage buffer (CullingMode::Coverage; shaders/shared/coverage_push.h,
// src/render/gpu/coverage_pass.h): the re-projection against a CPU
// reference written here (glm, double), the still camera giving the
// unculled frame, and the missed pixels of an orbit counted against
// culling off beside two-phase's zero. Coverage is NOT conservative: only
// what must hold is asserted; the counts are printed. Validation layers on
// (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "gpu/submit.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/tractogram_upload.h"
#include "shared/coverage_push.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

using test::renderPhantom;

constexpr uint32_t kWidth = 160, kHeight = 120;
constexpr uint64_t kEmpty = ~uint64_t(0);  // a visibility key nothing drew (shared/render_config.h)

RenderSettings plainSettings(CullingMode culling, float line_width) {
  RenderSettings settings;
  settings.culling = culling;
  settings.lod_pixels = 0;  // LoD off: the frames compare key for key
  settings.line_width_px = line_width;
  settings.ssao = false;
  return settings;
}

glm::dmat4 viewProjectionGlm(const Camera& camera) { return glm::make_mat4(viewProjectionD(camera).data()); }

// The world size of one pixel at view depth z, measured: two adjacent pixel
// centres unprojected at that depth.
double pixelWorldSize(const Camera& camera, double z) {
  const glm::dmat4 inverse = glm::inverse(viewProjectionGlm(camera));
  const glm::dmat4 projection = glm::make_mat4(projectionMatrixD(camera).data());
  // NDC depth of view depth z on the axis.
  const glm::dvec4 clip = projection * glm::dvec4(0, 0, -z, 1);
  const double d = clip.z / clip.w;
  auto at = [&](double px) {
    const glm::dvec4 h = inverse * glm::dvec4((px + 0.5) / camera.width * 2 - 1, 0, d, 1);
    return glm::dvec3(h) / h.w;
  };
  return glm::length(at(camera.width / 2.0 + 1) - at(camera.width / 2.0));
}

TEST(CoverageSplat, radiusCoversThePixelFootprint) {
  Camera camera;
  camera.width = kWidth;
  camera.height = kHeight;
  camera.fov_y_deg = 40;
  for (double z : {5.0, 80.0, 400.0}) {
    SCOPED_TRACE("z " + std::to_string(z));
    const double pixel = pixelWorldSize(camera, z);
    const double radius = coverageSplatRadiusMm(camera, float(z));
    // Half the pixel's diagonal: the disc holds the pixel's square, and no
    // more than that (a still camera's splat reaches no neighbour's centre).
    EXPECT_NEAR(radius, pixel * std::sqrt(0.5), pixel * 1e-4);
    EXPECT_LT(radius, pixel);
  }
}

// One re-projected sample as the CPU reference sees it.
struct Splat {
  glm::dvec2 centre;  // window coordinates in the new frame
  double radius_px = 0;
  double depth = 1;
};

Splat referenceSplat(const Camera& previous, const Camera& next, uint32_t px, uint32_t py, float depth) {
  const glm::dvec4 h = glm::inverse(viewProjectionGlm(previous)) *
                       glm::dvec4((px + 0.5) / previous.width * 2 - 1, (py + 0.5) / previous.height * 2 - 1, depth, 1);
  const glm::dvec3 world = glm::dvec3(h) / h.w;
  // R_S(z): half a pixel diagonal of the previous frame at the sample's view depth.
  const glm::dvec3 eye_prev(previous.eye[0], previous.eye[1], previous.eye[2]);
  const glm::dvec3 axis_prev =
      glm::normalize(glm::dvec3(previous.target[0], previous.target[1], previous.target[2]) - eye_prev);
  const double z_prev = glm::dot(world - eye_prev, axis_prev);
  const double radius = std::sqrt(0.5) * pixelWorldSize(previous, z_prev);
  const glm::dmat4 vp = viewProjectionGlm(next);
  const glm::dvec4 c = vp * glm::dvec4(world, 1);
  const glm::dvec3 eye(next.eye[0], next.eye[1], next.eye[2]);
  const glm::dvec4 b = vp * glm::dvec4(world + radius * glm::normalize(world - eye), 1);
  Splat s;
  s.centre = (glm::dvec2(c) / c.w + 1.0) * 0.5 * glm::dvec2(next.width, next.height);
  const glm::dmat4 projection = glm::make_mat4(projectionMatrixD(next).data());
  const double focal = std::abs(projection[1][1]) * 0.5 * next.height;
  s.radius_px = std::min(radius * focal / c.w, double(shader::kCoverageMaxSplatPixels));
  s.depth = b.z / b.w;
  return s;
}

class GpuCoverage : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    fibers_ = renderPhantom(600, 11);
    bounds_ = tractogramBounds(fibers_);
    upload_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers_, "phantom"));
  }
  void TearDown() override {
    upload_.reset();
    test::GpuTest::TearDown();
  }
  GpuScene scene() const { return GpuScene{&upload_->dataset}; }
  Camera orbit(double azimuth, double distance = 1.0) const {
    return orbitCamera(bounds_, azimuth, 20, kWidth, kHeight, distance);
  }

  // Per frame of an orbit from azimuth 30 at `step` degrees: pixels covered
  // with culling off and empty with `mode` (each renderer keeps its own
  // history), and the fraction of fiblets `mode` drew.
  struct Orbit {
    std::vector<uint64_t> missed;
    std::vector<uint64_t> changed;  // keys that differ at all: another fiber (or none) shows
    std::vector<double> drawn;
    uint64_t covered = 0;  // by the reference, over the frames
    uint64_t total() const { return std::accumulate(missed.begin(), missed.end(), uint64_t(0)); }
  };
  Orbit missedPixels(CullingMode mode, double step, int frames, float width) {
    FrameRenderer reference(context(), kWidth, kHeight), culled(context(), kWidth, kHeight);
    Orbit orbit_result;
    for (int f = 0; f < frames; ++f) {
      const Camera camera = orbit(30 + step * f);
      reference.render(camera, plainSettings(CullingMode::None, width), scene());
      const FrameStats stats = culled.render(camera, plainSettings(mode, width), scene());
      const auto a = downloadVisibility(context(), reference.targets());
      const auto b = downloadVisibility(context(), culled.targets());
      uint64_t missed = 0, changed = 0;
      for (size_t i = 0; i < a.size(); ++i) {
        orbit_result.covered += a[i] != kEmpty;
        missed += a[i] != kEmpty && b[i] == kEmpty;
        changed += a[i] != b[i];
      }
      orbit_result.missed.push_back(missed);
      orbit_result.changed.push_back(changed);
      orbit_result.drawn.push_back(double(stats.fiblets_drawn) / double(std::max<uint64_t>(stats.fiblets_total, 1)));
    }
    return orbit_result;
  }

  Tractogram fibers_;
  Bounds bounds_;
  std::unique_ptr<TractogramUpload> upload_;
};

TEST_F(GpuCoverage, reprojectionMatchesACpuReference) {
  // Frame N seen from farther away than the new frame, so the splats grow
  // to a few pixels and their discs are tested, not only their centres.
  const Camera previous = orbit(40, 1.0), next = orbit(52, 0.45);
  FrameRenderer renderer(context(), kWidth, kHeight);
  renderer.render(next, plainSettings(CullingMode::None, 1.0f), scene());  // writes next's camera block

  // A few samples of frame N (world points near the phantom's centre, at
  // their pixel centres and depths), far enough apart that discs rarely meet.
  const glm::dvec3 centre = 0.5 * (glm::dvec3(bounds_.min[0], bounds_.min[1], bounds_.min[2]) +
                                   glm::dvec3(bounds_.max[0], bounds_.max[1], bounds_.max[2]));
  const glm::dvec3 extent = glm::dvec3(bounds_.max[0], bounds_.max[1], bounds_.max[2]) - centre;
  const glm::dmat4 vp = viewProjectionGlm(previous);
  std::vector<uint64_t> keys(shader::visibilityKeyCount(kWidth, kHeight), kEmpty);
  std::vector<Splat> splats;
  for (int i = 0; i < 12; ++i) {
    const glm::dvec3 p =
        centre + extent * glm::dvec3(0.3 * std::sin(1.7 * i), 0.3 * std::cos(2.3 * i), 0.3 * std::sin(0.9 * i + 1));
    const glm::dvec4 c = vp * glm::dvec4(p, 1);
    const uint32_t px = uint32_t((c.x / c.w + 1) * 0.5 * kWidth), py = uint32_t((c.y / c.w + 1) * 0.5 * kHeight);
    const float depth = float(c.z / c.w);
    uint64_t& key = keys[shader::visibilityIndex(px, py, kWidth)];
    if (key != kEmpty) continue;
    key = shader::visibilityKey(depth, uint64_t(i));
    splats.push_back(referenceSplat(previous, next, px, py, depth));
  }
  ASSERT_GE(splats.size(), 8u);

  CullPasses passes = createCullPasses(context());
  CullBuffers buffers;
  prepareCullBuffers(context(), buffers, 1, kWidth, kHeight, /*coverage=*/true);
  buffers.coverage.camera = previous;
  gpu::uploadToBuffer(context(), buffers.coverage.previous_keys, keys.data(), keys.size() * sizeof(uint64_t));
  gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, buffers.pyramid.buffer, 0, uint64_t(kWidth) * kHeight * sizeof(float),
                    shader::kCoverageFarBits);
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    recordCoverageReproject(cmd, passes.coverage, buffers.coverage, next, renderer.targets(), buffers.pyramid.address);
  });
  std::vector<float> coverage(size_t(kWidth) * kHeight);
  gpu::downloadFromBuffer(context(), buffers.pyramid, coverage.data(), coverage.size() * sizeof(float));
  destroyCullBuffers(context(), buffers);
  destroyCullPasses(context(), passes);

  size_t covered = 0, compared = 0;
  double largest_radius = 0;
  for (const Splat& s : splats) largest_radius = std::max(largest_radius, s.radius_px);
  for (uint32_t y = 0; y < kHeight; ++y)
    for (uint32_t x = 0; x < kWidth; ++x) {
      double expected = 1;
      bool ambiguous = false;
      for (const Splat& s : splats) {
        const double d = glm::length(glm::dvec2(x + 0.5, y + 0.5) - s.centre);
        if (std::abs(d - s.radius_px) < 1e-3) ambiguous = true;  // float rounding decides
        if (d <= s.radius_px) expected = std::min(expected, s.depth);
      }
      if (ambiguous) continue;
      ++compared;
      const float got = coverage[size_t(y) * kWidth + x];
      covered += expected < 1;
      ASSERT_NEAR(got, expected, 2e-5) << "pixel " << x << ", " << y;
    }
  std::printf("coverage re-projection: %zu samples, discs up to %.2f px, %zu pixels covered, %zu compared\n",
              splats.size(), largest_radius, covered, compared);
  EXPECT_GT(largest_radius, 1.0) << "the zoom makes discs of more than one pixel";
  EXPECT_GT(covered, splats.size()) << "discs cover more than their centres";
}

TEST_F(GpuCoverage, stillCameraGivesTheUnculledFrameAndCullsOccludedFiblets) {
  // Width 4 on a dense view: bundles hide each other (as two-phase's test).
  const Camera camera = orbitCamera(bounds_, 60, 25, kWidth, kHeight, 1.0);
  FrameRenderer reference(context(), kWidth, kHeight), culled(context(), kWidth, kHeight),
      frustum(context(), kWidth, kHeight);
  reference.render(camera, plainSettings(CullingMode::None, 4.0f), scene());
  const FrameStats frustum_stats = frustum.render(camera, plainSettings(CullingMode::Frustum, 4.0f), scene());
  const auto keys = downloadVisibility(context(), reference.targets());
  size_t covered = 0;
  for (uint64_t k : keys) covered += k != kEmpty;
  ASSERT_GT(covered, size_t(kWidth) * kHeight / 10) << "the view shows the phantom";
  for (int frame = 0; frame < 3; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    const FrameStats stats = culled.render(camera, plainSettings(CullingMode::Coverage, 4.0f), scene());
    const auto got = downloadVisibility(context(), culled.targets());
    size_t key_diff = 0;
    for (size_t i = 0; i < keys.size(); ++i) key_diff += keys[i] != got[i];
    EXPECT_EQ(key_diff, 0u) << "of " << covered << " covered pixels";
    bool has_coverage = false;
    for (const PassTiming& p : stats.passes) has_coverage |= p.name == "coverage";
    std::printf("coverage, still camera, frame %d: %llu of %llu fiblets drawn (frustum: %llu)\n", frame,
                static_cast<unsigned long long>(stats.fiblets_drawn),
                static_cast<unsigned long long>(stats.fiblets_total),
                static_cast<unsigned long long>(frustum_stats.fiblets_drawn));
    if (frame == 0) {
      EXPECT_FALSE(has_coverage) << "no previous frame: frustum culling only";
      EXPECT_EQ(stats.fiblets_drawn, frustum_stats.fiblets_drawn);
    } else {
      EXPECT_TRUE(has_coverage);
      EXPECT_LT(stats.fiblets_drawn, frustum_stats.fiblets_drawn) << "fiblets behind the coverage are skipped";
    }
  }
}

TEST_F(GpuCoverage, missedPixelsOfAnOrbitBesideTwoPhase) {
  constexpr int kFrames = 6;
  constexpr float kLineWidth = 4.0f;
  const Orbit two_small = missedPixels(CullingMode::TwoPhase, 1.14, kFrames, kLineWidth);
  const Orbit two_large = missedPixels(CullingMode::TwoPhase, 60, kFrames, kLineWidth);
  const Orbit cov_small = missedPixels(CullingMode::Coverage, 1.14, kFrames, kLineWidth);
  const Orbit cov_large = missedPixels(CullingMode::Coverage, 60, kFrames, kLineWidth);
  auto print = [](const char* name, const Orbit& o) {
    std::printf("%-22s missed pixels per frame:", name);
    for (uint64_t m : o.missed) std::printf(" %llu", static_cast<unsigned long long>(m));
    const double drawn = std::accumulate(o.drawn.begin() + 1, o.drawn.end(), 0.0) / double(o.drawn.size() - 1);
    const uint64_t changed = std::accumulate(o.changed.begin(), o.changed.end(), uint64_t(0));
    std::printf("  (total %llu of %llu covered, %llu keys changed; fiblets drawn after the first frame %.3f)\n",
                static_cast<unsigned long long>(o.total()), static_cast<unsigned long long>(o.covered),
                static_cast<unsigned long long>(changed), drawn);
  };
  print("two-phase, 1.14 deg:", two_small);
  print("two-phase, 60 deg:", two_large);
  print("coverage, 1.14 deg:", cov_small);
  print("coverage, 60 deg:", cov_large);
  EXPECT_EQ(two_small.total(), 0u) << "two-phase is conservative";
  EXPECT_EQ(two_large.total(), 0u) << "two-phase is conservative";
  for (const Orbit* o : {&two_small, &two_large})
    EXPECT_EQ(std::accumulate(o->changed.begin(), o->changed.end(), uint64_t(0)), 0u) << "bit for bit";
  EXPECT_EQ(cov_small.missed[0], 0u) << "the first frame has no history: frustum culling only";
  EXPECT_EQ(cov_large.missed[0], 0u);
  // Not asserted: that 60-degree steps miss more than 1.14-degree ones. It
  // does not hold robustly: a large step re-projects the last frame's
  // samples so sparsely that the pyramid's max over a fiblet's rectangle
  // nearly always meets an uncovered pixel and little is culled at all
  // (99 % drawn here, 99.4 % in docs/BENCHMARKS.md, where 1.14 degrees
  // missed 3 pixels and 60 none).
}

}  // namespace
}  // namespace fibscope
