// The cull passes of the compute pipeline (DESIGN.md section 6, step 1;
// src/render/gpu/cull_passes.h): culling must be conservative, so two-phase
// occlusion culling and frustum culling with LoD off give the SAME frame as
// drawing every fiblet (visibility keys, hence coverage, depth and fiber
// ids, bit for bit) on every frame of an orbit, across a 60 degree jump
// and a zoom; they must still cull something; the far-view LoD keeps the
// image. Validation layers on (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "gpu/submit.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/camera.h"
#include "render/gpu/cull_passes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "shared/cull_push.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

using test::gbufferMask;
using test::renderPhantom;

// Small enough for lavapipe (the raster dominates: about 0.1 s a frame at
// width 4), large enough for the phantom's bundles to occlude each other.
constexpr uint32_t kSize = 160;

// Settings without the shading passes' extras, so frames are cheap.
RenderSettings plainSettings(CullingMode culling, float lod_pixels, float line_width) {
  RenderSettings settings;
  settings.culling = culling;
  settings.lod_pixels = lod_pixels;
  settings.line_width_px = line_width;
  settings.ssao = false;
  return settings;
}

// One frame rendered by two renderers, compared texel by texel.
struct FrameDiff {
  size_t covered = 0;        // pixels the reference covers
  size_t coverage_diff = 0;  // covered in one and not the other
  size_t fiber_diff = 0;     // covered in both, different fiber
  size_t key_diff = 0;       // visibility keys that differ
  FrameStats culled;         // the culled renderer's statistics
};

FrameDiff renderBoth(const gpu::VulkanContext& context, FrameRenderer& reference, FrameRenderer& culled,
                     const Camera& camera, const RenderSettings& reference_settings,
                     const RenderSettings& culled_settings, const GpuDataset& dataset) {
  FrameDiff diff;
  reference.render(camera, reference_settings, GpuScene{&dataset});
  diff.culled = culled.render(camera, culled_settings, GpuScene{&dataset});
  const auto a = downloadGBuffer(context, reference.targets());
  const auto b = downloadGBuffer(context, culled.targets());
  const auto keys_a = downloadVisibility(context, reference.targets());
  const auto keys_b = downloadVisibility(context, culled.targets());
  for (size_t i = 0; i < a.size(); ++i) {
    const bool ca = a[i].fiber != shader::kNoFiberId, cb = b[i].fiber != shader::kNoFiberId;
    diff.covered += ca;
    diff.coverage_diff += ca != cb;
    diff.fiber_diff += ca && cb && a[i].fiber != b[i].fiber;
    diff.key_diff += keys_a[i] != keys_b[i];
  }
  return diff;
}

double fraction(const FrameStats& stats) {
  return stats.fiblets_total > 0 ? double(stats.fiblets_drawn + stats.fiblets_lod) / double(stats.fiblets_total) : 0;
}

class GpuCulling : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    fibers_ = renderPhantom(600, 11);
    bounds_ = tractogramBounds(fibers_);
    upload_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers_, "phantom"));
  }
  void TearDown() override {
    upload_.reset();  // before the device goes
    test::GpuTest::TearDown();
  }
  const GpuDataset& dataset() const { return upload_->dataset; }

  Tractogram fibers_;
  Bounds bounds_;
  std::unique_ptr<TractogramUpload> upload_;
};

TEST_F(GpuCulling, twoPhaseCullingKeepsEveryVisiblePixel) {
  struct Frame {
    double azimuth, elevation, distance;
  };
  std::vector<Frame> orbit;
  for (int i = 0; i < 12; ++i) orbit.push_back({30 + 1.14 * i, 20, 1.0});  // 1.14 degrees a frame
  orbit.push_back({30 + 1.14 * 11 + 60, 20, 1.0});                         // a 60 degree jump
  orbit.push_back({30 + 1.14 * 12 + 60, 20, 1.0});
  orbit.push_back({30 + 1.14 * 12 + 60, 20, 0.5});  // zoom in: part of the phantom leaves the frame
  orbit.push_back({30 + 1.14 * 13 + 60, 20, 0.5});
  orbit.push_back({30 + 1.14 * 13 + 60, 20, 1.5});  // zoom out
  // Width 1 on a shorter path (a few orbit frames, the jump, the zoom): the
  // whole path at both widths would take twice the time for little more.
  const std::vector<Frame> short_path = {orbit[0], orbit[1], orbit[12], orbit[14]};
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  for (float width : {2.5f, 1.0f}) {
    const std::vector<Frame>& frames = width > 1.0f ? orbit : short_path;
    const RenderSettings none = plainSettings(CullingMode::None, 0, width);
    const RenderSettings two_phase = plainSettings(CullingMode::TwoPhase, 0, width);
    double min_fraction = 1, max_fraction = 0;
    for (size_t f = 0; f < frames.size(); ++f) {
      SCOPED_TRACE("width " + std::to_string(width) + ", frame " + std::to_string(f));
      const Camera camera =
          orbitCamera(bounds_, frames[f].azimuth, frames[f].elevation, kSize, kSize, frames[f].distance);
      const FrameDiff d = renderBoth(context(), reference, culled, camera, none, two_phase, dataset());
      ASSERT_GT(d.covered, kSize * kSize / 20) << "the view shows the phantom";
      EXPECT_EQ(d.coverage_diff, 0u) << "of " << d.covered << " covered pixels";
      EXPECT_EQ(d.fiber_diff, 0u);
      EXPECT_EQ(d.key_diff, 0u) << "the visibility buffers differ";
      EXPECT_EQ(d.culled.fiblets_lod, 0u) << "LoD is off";
      EXPECT_LE(d.culled.fiblets_drawn, d.culled.fiblets_total);
      if (f > 0) {  // the first frame draws everything in the frustum
        min_fraction = std::min(min_fraction, fraction(d.culled));
        max_fraction = std::max(max_fraction, fraction(d.culled));
      }
    }
    std::printf("two-phase, width %.1f: %zu frames compared; fiblets drawn %.3f .. %.3f of the total\n", width,
                frames.size(), min_fraction, max_fraction);
  }
}

TEST_F(GpuCulling, frustumCullingIsConservative) {
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  const struct { double azimuth, elevation, distance; } views[] = {{20, 10, 0.3}, {110, -25, 0.4}, {290, 5, 0.5}};
  for (float width : {1.0f, 4.0f}) {
    const RenderSettings none = plainSettings(CullingMode::None, 0, width);
    const RenderSettings frustum = plainSettings(CullingMode::Frustum, 0, width);
    for (const auto& v : views) {
      SCOPED_TRACE("width " + std::to_string(width) + ", distance " + std::to_string(v.distance));
      const Camera camera = orbitCamera(bounds_, v.azimuth, v.elevation, kSize, kSize, v.distance);
      const FrameDiff d = renderBoth(context(), reference, culled, camera, none, frustum, dataset());
      ASSERT_GT(d.covered, kSize * kSize / 20) << "the view shows the phantom";
      EXPECT_EQ(d.coverage_diff, 0u) << "of " << d.covered << " covered pixels";
      EXPECT_EQ(d.fiber_diff, 0u);
      EXPECT_EQ(d.key_diff, 0u) << "the visibility buffers differ";
      EXPECT_LT(d.culled.fiblets_drawn, d.culled.fiblets_total) << "a close-up leaves fiblets off screen";
      EXPECT_EQ(d.culled.fiblets_lod, 0u);
      std::printf("frustum, width %.0f, distance %.2f: fiblets drawn %.3f of %llu\n", width, v.distance,
                  fraction(d.culled), static_cast<unsigned long long>(d.culled.fiblets_total));
    }
  }
}

TEST_F(GpuCulling, twoPhaseCullsOccludedFibletsOnADenseView) {
  FrameRenderer renderer(context(), kSize, kSize);
  const RenderSettings two_phase = plainSettings(CullingMode::TwoPhase, 0, 4.0f);
  const Camera camera = orbitCamera(bounds_, 60, 25, kSize, kSize, 1.0);
  FrameStats first, steady;
  for (int frame = 0; frame < 4; ++frame) {
    const FrameStats stats = renderer.render(camera, two_phase, GpuScene{&dataset()});
    if (frame == 0) first = stats;
    steady = stats;
  }
  std::printf("two-phase, dense view (width 4): first frame %.3f, steady state %.3f of %llu fiblets drawn\n",
              fraction(first), fraction(steady), static_cast<unsigned long long>(steady.fiblets_total));
  // The first frame draws every fiblet that draws anything (fiblets of a
  // single point that end their fiber draw nothing, and are culled).
  EXPECT_GE(first.fiblets_drawn, first.fiblets_total * 99 / 100) << "the whole phantom is in view";
  EXPECT_LT(steady.fiblets_drawn, first.fiblets_drawn) << "some fiblets are hidden behind others";
  // The time per pass includes the cull, pyramid and both phases.
  bool has_pyramid = false;
  for (const PassTiming& p : steady.passes) has_pyramid |= p.name == "depth pyramid";
  EXPECT_TRUE(has_pyramid);
}

TEST_F(GpuCulling, lodKeepsTheImage) {
  FrameRenderer full(context(), kSize, kSize), lod(context(), kSize, kSize);
  // Far views (every fiblet a few pixels) with Frustum, and a nearer one
  // where LoD and full fiblets mix, with TwoPhase (LoD in both phases).
  const struct {
    double distance;
    CullingMode mode;
  } views[] = {{4.0, CullingMode::Frustum}, {6.0, CullingMode::Frustum}, {2.0, CullingMode::TwoPhase}};
  for (const auto& v : views) {
    SCOPED_TRACE("distance " + std::to_string(v.distance));
    const Camera camera = orbitCamera(bounds_, 45, 30, kSize, kSize, v.distance);
    full.render(camera, plainSettings(CullingMode::None, 0, 1.0f), GpuScene{&dataset()});
    FrameStats stats;
    for (int frame = 0; frame < 2; ++frame)  // TwoPhase: the second frame uses the first one's history
      stats = lod.render(camera, plainSettings(v.mode, 4.0f, 1.0f), GpuScene{&dataset()});
    const auto a = downloadGBuffer(context(), full.targets());
    const auto b = downloadGBuffer(context(), lod.targets());
    const CoverageComparison c = compareCoverage(gbufferMask(a), gbufferMask(b), kSize, kSize);
    std::printf("LoD (%s) at distance %.0f: %llu of %llu fiblets as one segment, %llu full; %s\n",
                std::string(cullingModeName(v.mode)).c_str(), v.distance,
                static_cast<unsigned long long>(stats.fiblets_lod),
                static_cast<unsigned long long>(stats.fiblets_total),
                static_cast<unsigned long long>(stats.fiblets_drawn), c.summary().c_str());
    ASSERT_GT(c.covered_a, 100u) << "the view shows the phantom";
    EXPECT_GT(stats.fiblets_lod, 0u);
    EXPECT_GE(c.agreement, 0.95) << c.summary();
    EXPECT_LE(c.maxDistance(), 2.0) << c.summary();
    // The LoD segment's payload names its fiblet, so covered pixels carry
    // real fiber ids; far away many fibers share a pixel and the simplified
    // segments change which one is in front (77 % agree at distance 6).
    size_t both = 0, same = 0;
    for (size_t i = 0; i < a.size(); ++i) {
      if (a[i].fiber == shader::kNoFiberId || b[i].fiber == shader::kNoFiberId) continue;
      ++both;
      same += a[i].fiber == b[i].fiber;
    }
    EXPECT_GE(double(same), 0.6 * double(both)) << same << " of " << both;
  }
}

TEST_F(GpuCulling, depthPyramidHoldsTheFarthestDepthOverEachTexel) {
  // An odd size, so that levels have texels with fewer than four children.
  constexpr uint32_t kWidth = 75, kHeight = 41;
  FrameRenderer renderer(context(), kWidth, kHeight);
  const Camera camera = orbitCamera(bounds_, 10, 15, kWidth, kHeight, 0.8);
  renderer.render(camera, plainSettings(CullingMode::None, 0, 2.0f), GpuScene{&dataset()});
  const std::vector<uint64_t> keys = downloadVisibility(context(), renderer.targets());

  CullPasses passes = createCullPasses(context());
  CullBuffers buffers;
  prepareCullBuffers(context(), buffers, 1, kWidth, kHeight);
  gpu::submitOnce(context(),
                  [&](VkCommandBuffer cmd) { recordDepthPyramid(cmd, passes, renderer.targets(), buffers); });
  const uint32_t levels = shader::pyramidLevelCount(kWidth, kHeight);
  std::vector<float> pyramid(shader::pyramidLevelOffset(kWidth, kHeight, levels));
  gpu::downloadFromBuffer(context(), buffers.pyramid, pyramid.data(), pyramid.size() * sizeof(float));
  destroyCullBuffers(context(), buffers);
  destroyCullPasses(context(), passes);

  EXPECT_EQ(levels, 8u);  // 75 x 41, 38 x 21, 19 x 11, 10 x 6, 5 x 3, 3 x 2, 2 x 1, 1 x 1
  size_t covered = 0;
  for (uint64_t key : keys) covered += key != ~uint64_t(0);
  ASSERT_GT(covered, 100u);
  ASSERT_LT(covered, keys.size()) << "some pixels are empty (depth 1)";
  // Brute force: texel (x, y) of level L is the max over level-0 pixels
  // [x << L, (x + 1) << L) x [y << L, (y + 1) << L) within the frame.
  for (uint32_t level = 0; level < levels; ++level) {
    const uint32_t w = shader::pyramidLevelSize(kWidth, level), h = shader::pyramidLevelSize(kHeight, level);
    const uint32_t offset = shader::pyramidLevelOffset(kWidth, kHeight, level);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        float expected = 0;
        for (uint32_t py = y << level; py < std::min((y + 1) << level, kHeight); ++py)
          for (uint32_t px = x << level; px < std::min((x + 1) << level, kWidth); ++px) {
            const uint64_t key = keys[size_t(py) * kWidth + px];
            expected = std::max(expected, key == ~uint64_t(0) ? 1.0f : shader::visibilityDepth(key));
          }
        ASSERT_EQ(pyramid[offset + y * w + x], expected) << "level " << level << " texel " << x << ", " << y;
      }
  }
  EXPECT_EQ(pyramid.back(), 1.0f) << "the top texel sees an empty pixel";
}

}  // namespace
}  // namespace fibscope
