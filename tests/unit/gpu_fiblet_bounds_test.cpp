// Per-fiblet bounding spheres (render/gpu/fiblet_bounds.h,
// shaders/fiblet_bounds.comp): every point a fiblet draws, decoded on the
// CPU in both composition orders (the serial rasters' and the
// parallel-prefix scan's) and the joining point, lies inside the sphere the
// GPU computed; fiblets that draw nothing are marked; the spheres are much
// tighter than the record-only bound the cull falls back to; and culling
// with or without them draws the frame bit for bit as drawing everything.
// Validation layers on (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "codec/fiblet_decoder.h"
#include "gpu/buffer.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/fiblet_bounds.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/tractogram_upload.h"
#include "shared/cull_push.h"
#include "shared/fiblet.h"

namespace fibscope {
namespace {

constexpr uint32_t kSize = 128;

// One fiblet as the rasters see it, in world mm (float, as fibletToWorld).
struct DecodedFiblet {
  uint32_t count = 0;
  bool joins = false;
  std::vector<std::array<float, 3>> scan, sequential;  // the decoded points in both orders
  std::array<float, 3> joining{};                      // the next fiblet's first point, when joins
};

class GpuFibletBounds : public test::GpuTest {
 protected:
  void upload(const Tractogram& fibers) {
    upload_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers, "phantom"));
    ASSERT_FALSE(dataset().fibletBoundsReady()) << "not at upload: when the occlusion cull first needs them";
    dataset().computeFibletBounds();
    const shader::FibletDataset& block = dataset().block();
    const uint32_t record_bytes = upload_->params.recordBytes();
    records_.resize(size_t(block.fiblet_count) * record_bytes);
    gpu::downloadFromBuffer(context(), dataset().records(), records_.data(), records_.size());
    spheres_.resize(block.fiblet_count);
    gpu::downloadFromBuffer(context(), dataset().fibletBounds(), spheres_.data(), spheres_.size() * sizeof(shader::vec4));
  }
  void TearDown() override {
    upload_.reset();  // before the device goes
    test::GpuTest::TearDown();
  }
  GpuDataset& dataset() { return upload_->dataset; }

  std::array<float, 3> toWorld(const float* p) const {
    const shader::FibletDataset& b = upload_->dataset.block();
    return {b.translation_x + b.mm_per_unit * p[0], b.translation_y + b.mm_per_unit * p[1],
            b.translation_z + b.mm_per_unit * p[2]};
  }
  const uint8_t* record(size_t fiblet) const { return records_.data() + fiblet * upload_->params.recordBytes(); }
  std::array<float, 3> firstPoint(size_t fiblet) const {
    const uint8_t* r = record(fiblet);
    float p[3];
    for (int c = 0; c < 3; ++c) p[c] = shader::fibletDequantize(uint32_t(r[2 * c]) | uint32_t(r[2 * c + 1]) << 8);
    return toWorld(p);
  }

  DecodedFiblet decode(const FibletDecoder& decoder, size_t fiblet) const {
    const uint32_t n = upload_->params.points_per_fiblet;
    const uint32_t flags = record(fiblet)[shader::fibletFlagsByte(n)];
    DecodedFiblet d;
    std::vector<float> xyz(3 * n);
    for (DecodeOrder order : {DecodeOrder::Scan, DecodeOrder::Sequential}) {
      d.count = decoder.decode(record(fiblet), xyz.data(), order);
      auto& points = order == DecodeOrder::Scan ? d.scan : d.sequential;
      for (uint32_t k = 0; k < d.count; ++k) points.push_back(toWorld(&xyz[3 * k]));
    }
    d.joins = (flags & shader::kFibletFlagEnds) == 0 && fiblet + 1 < spheres_.size();
    if (d.joins) d.joining = firstPoint(fiblet + 1);
    return d;
  }

  // fiblet_cull.comp's fallback radius (record only, centred on p0), mm.
  double recordRadius(const DecodedFiblet& d, size_t fiblet) const {
    const shader::FibletDataset& b = upload_->dataset.block();
    const uint8_t* r = record(fiblet);
    float p[2][3];
    for (int k = 0; k < 2; ++k)
      for (int c = 0; c < 3; ++c)
        p[k][c] = shader::fibletDequantize(uint32_t(r[6 * k + 2 * c]) | uint32_t(r[6 * k + 2 * c + 1]) << 8);
    double radius = 0;
    if (d.count >= 2)
      radius = std::hypot(p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]) + (d.count - 2.0) * b.delta;
    if (d.joins) {
      const std::array<float, 3> p0 = toWorld(p[0]);
      radius = std::max(radius, std::hypot(d.joining[0] - p0[0], d.joining[1] - p0[1], d.joining[2] - p0[2]) /
                                    double(b.mm_per_unit));
    }
    return radius * b.mm_per_unit * (1.0 + shader::kCullRadiusSlack);
  }

  static double distance(const shader::vec4& s, const std::array<float, 3>& p) {
    return std::hypot(double(p[0]) - s.x, double(p[1]) - s.y, double(p[2]) - s.z);
  }

  std::unique_ptr<TractogramUpload> upload_;
  std::vector<uint8_t> records_;
  std::vector<shader::vec4> spheres_;
};

TEST_F(GpuFibletBounds, everyDrawnPointLiesInsideItsSphere) {
  upload(test::renderPhantom(300, 7));
  ASSERT_NE(dataset().block().fiblet_bounds, 0u);
  EXPECT_EQ(dataset().block().fiblet_bounds, dataset().fibletBounds().address);
  const FibletDecoder decoder(upload_->params);
  size_t outside = 0, points = 0, drawing = 0;
  double max_used = 0;  // largest distance / radius over every point
  double max_order_diff = 0;  // scan against sequential, mm
  for (size_t i = 0; i < spheres_.size(); ++i) {
    const DecodedFiblet d = decode(decoder, i);
    const shader::vec4& s = spheres_[i];
    ASSERT_GE(d.count, 1u) << "fiblet " << i;
    if (d.count < 2 && !d.joins) {
      EXPECT_LT(s.w, 0.0f) << "fiblet " << i << " draws nothing";
      continue;
    }
    ++drawing;
    ASSERT_GE(s.w, 0.0f) << "fiblet " << i << " draws";
    std::vector<std::array<float, 3>> all = d.scan;
    all.insert(all.end(), d.sequential.begin(), d.sequential.end());
    if (d.joins) all.push_back(d.joining);
    for (const auto& p : all) {
      const double r = distance(s, p);
      max_used = std::max(max_used, r / std::max(double(s.w), 1e-30));
      if (r > s.w && outside++ < 5) ADD_FAILURE() << "fiblet " << i << ": a point " << r << " mm from the centre, radius " << s.w;
      ++points;
    }
    for (uint32_t k = 0; k < d.count; ++k)
      for (int c = 0; c < 3; ++c)
        max_order_diff = std::max(max_order_diff, double(std::fabs(d.scan[k][c] - d.sequential[k][c])));
  }
  EXPECT_EQ(outside, 0u) << "of " << points << " points";
  // The spheres are tight: the farthest point is within the slack of the
  // radius (a sphere far too large would pass the test above).
  EXPECT_GT(max_used, 0.99);
  const shader::FibletDataset& b = dataset().block();
  std::printf("%zu of %zu fiblets draw; %zu points inside their spheres; farthest point at %.5f of the radius; "
              "scan vs sequential decode differ by at most %.2e mm (absolute slack %.2e mm)\n",
              drawing, spheres_.size(), points, max_used, max_order_diff,
              double(shader::kCullBoundsSlack) * b.mm_per_unit);
  EXPECT_LT(max_order_diff, double(shader::kCullBoundsSlack) * b.mm_per_unit / 10)
      << "the absolute slack leaves a tenfold margin over the decode orders' difference";
}

TEST_F(GpuFibletBounds, fibletsThatDrawNothingAreMarked) {
  // Streamlines of one point (a fiblet that begins and ends its fiber) and
  // of N + 1 points (a last fiblet of one point, whose segment to it is the
  // previous fiblet's joining segment).
  upload(test::lineTractogram({1, 7, 61, 1, 121, 2}));
  const FibletDecoder decoder(upload_->params);
  size_t nothing = 0;
  for (size_t i = 0; i < spheres_.size(); ++i) {
    const DecodedFiblet d = decode(decoder, i);
    const bool draws = d.count >= 2 || d.joins;
    EXPECT_EQ(spheres_[i].w >= 0.0f, draws) << "fiblet " << i << " of " << d.count << " points";
    nothing += !draws;
    if (!draws) continue;
    for (const auto& p : d.sequential) EXPECT_LE(distance(spheres_[i], p), spheres_[i].w) << "fiblet " << i;
    if (d.joins) {
      EXPECT_LE(distance(spheres_[i], d.joining), spheres_[i].w) << "fiblet " << i;
    }
  }
  EXPECT_GE(nothing, 2u) << "the one-point streamlines at least";
}

TEST_F(GpuFibletBounds, spheresAreMuchTighterThanTheRecordBound) {
  upload(test::renderPhantom(300, 7));
  const FibletDecoder decoder(upload_->params);
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < spheres_.size(); ++i) {
    if (spheres_[i].w < 0) continue;
    const DecodedFiblet d = decode(decoder, i);
    const double old_radius = recordRadius(d, i);
    ASSERT_GT(old_radius, 0.0) << "fiblet " << i;
    sum += spheres_[i].w / old_radius;
    ++n;
  }
  ASSERT_GT(n, 0u);
  const double mean = sum / double(n);
  std::printf("mean radius, precomputed / record bound: %.3f over %zu fiblets (N = %u)\n", mean, n,
              upload_->params.points_per_fiblet);
  EXPECT_LT(mean, 0.7);

  // Recomputing gives the same bits (the pass is deterministic), and costs
  // little next to the upload.
  const auto start = std::chrono::steady_clock::now();
  computeFibletBounds(context(), dataset().blockAddress(), dataset().fibletBounds().address,
                      dataset().block().fiblet_count);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::vector<shader::vec4> again(spheres_.size());
  gpu::downloadFromBuffer(context(), dataset().fibletBounds(), again.data(), again.size() * sizeof(shader::vec4));
  EXPECT_EQ(std::memcmp(again.data(), spheres_.data(), again.size() * sizeof(shader::vec4)), 0);
  std::printf("bounds pass (pipeline creation included): %.1f ms for %zu fiblets on %s\n", ms, spheres_.size(),
              context().info().name.c_str());
}

TEST_F(GpuFibletBounds, cullingWithAndWithoutSpheresDrawsTheSameFrames) {
  const Tractogram fibers = test::renderPhantom(400, 3);
  const Bounds bounds = tractogramBounds(fibers);
  upload(fibers);
  RenderSettings none;
  none.culling = CullingMode::None;
  none.lod_pixels = 0;
  none.ssao = false;
  FrameRenderer reference(context(), kSize, kSize);
  const struct { double azimuth, elevation, distance; } views[] = {{30, 20, 1.0}, {31.14, 20, 1.0}, {91, 20, 0.5}};
  for (CullingMode mode : {CullingMode::TwoPhase, CullingMode::Frustum}) {
    double drawn[2] = {0, 0};
    for (bool use : {true, false}) {
      dataset().useFibletBounds(use);
      ASSERT_EQ(dataset().block().fiblet_bounds != 0, use);
      FrameRenderer culled(context(), kSize, kSize);
      RenderSettings settings = none;
      settings.culling = mode;
      for (const auto& v : views) {
        SCOPED_TRACE(std::string(use ? "spheres" : "record bound") + ", distance " + std::to_string(v.distance));
        const Camera camera = orbitCamera(bounds, v.azimuth, v.elevation, kSize, kSize, v.distance);
        reference.render(camera, none, GpuScene{&dataset()});
        const FrameStats stats = culled.render(camera, settings, GpuScene{&dataset()});
        const auto a = downloadVisibility(context(), reference.targets());
        const auto b = downloadVisibility(context(), culled.targets());
        size_t differ = 0, covered = 0;
        for (size_t i = 0; i < a.size(); ++i) {
          differ += a[i] != b[i];
          covered += a[i] != ~uint64_t(0);
        }
        ASSERT_GT(covered, size_t(kSize) * kSize / 20) << "the view shows the phantom";
        EXPECT_EQ(differ, 0u) << "visibility keys differ from drawing everything";
        drawn[use ? 0 : 1] += double(stats.fiblets_drawn) / double(stats.fiblets_total);
      }
    }
    std::printf("%s: fiblets drawn (mean of %zu views) %.3f with the spheres, %.3f with the record bound\n",
                mode == CullingMode::TwoPhase ? "two-phase" : "frustum", std::size(views), drawn[0] / std::size(views),
                drawn[1] / std::size(views));
    EXPECT_LE(drawn[0], drawn[1]) << "tighter spheres never draw more";
  }
  dataset().useFibletBounds(true);
}

// The spheres cost a decode of every fiblet (about 1 us a fiblet on
// lavapipe), so they are not made at upload: the first frame that culls by
// occlusion records them; frames with frustum culling (a one-frame render)
// never pay for them. The spheres made in a frame equal those computed
// alone.
TEST_F(GpuFibletBounds, theFirstOcclusionCulledFrameComputesTheSpheres) {
  const Tractogram fibers = test::renderPhantom(300, 5);
  TractogramUpload lazy = uploadTractogram(context(), fibers, "phantom");
  ASSERT_FALSE(lazy.dataset.fibletBoundsReady());
  EXPECT_EQ(lazy.dataset.block().fiblet_bounds, 0u);
  const Camera camera = orbitCamera(tractogramBounds(fibers), 40, 15, kSize, kSize, 1.0);
  RenderSettings settings;
  settings.ssao = false;
  FrameRenderer renderer(context(), kSize, kSize);
  settings.culling = CullingMode::Frustum;
  renderer.render(camera, settings, GpuScene{&lazy.dataset});
  EXPECT_FALSE(lazy.dataset.fibletBoundsReady()) << "frustum culling keeps the record's bound";
  settings.culling = CullingMode::TwoPhase;
  const FrameStats stats = renderer.render(camera, settings, GpuScene{&lazy.dataset});
  ASSERT_TRUE(lazy.dataset.fibletBoundsReady());
  EXPECT_EQ(lazy.dataset.block().fiblet_bounds, lazy.dataset.fibletBounds().address);
  bool timed = false;
  for (const auto& pass : stats.passes) timed |= pass.name == "fiblet bounds";
  EXPECT_TRUE(timed) << "the frame that made them times them";
  // The block on the device names the spheres too.
  shader::FibletDataset on_device{};
  gpu::downloadFromBuffer(context(), lazy.dataset.blockBuffer(), &on_device, sizeof on_device);
  EXPECT_EQ(on_device.fiblet_bounds, lazy.dataset.fibletBounds().address);
  // Bit for bit what the stand-alone computation gives.
  const uint32_t n = lazy.dataset.block().fiblet_count;
  std::vector<shader::vec4> in_frame(n), alone(n);
  gpu::downloadFromBuffer(context(), lazy.dataset.fibletBounds(), in_frame.data(), n * sizeof(shader::vec4));
  upload(fibers);  // the fixture's dataset, computed by computeFibletBounds
  ASSERT_EQ(dataset().block().fiblet_count, n);
  gpu::downloadFromBuffer(context(), dataset().fibletBounds(), alone.data(), n * sizeof(shader::vec4));
  EXPECT_EQ(std::memcmp(in_frame.data(), alone.data(), n * sizeof(shader::vec4)), 0);
  // A later two-phase frame does not make them again.
  const FrameStats later = renderer.render(camera, settings, GpuScene{&lazy.dataset});
  for (const auto& pass : later.passes) EXPECT_NE(pass.name, "fiblet bounds");
}

}  // namespace
}  // namespace fibscope
