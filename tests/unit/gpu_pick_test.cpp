// Picking against the G-buffer it reads and the CPU reference rasteriser
// (reference_raster.h): a phantom is rendered through FrameRenderer, pixels
// are picked one by one, and the result must be the downloaded G-buffer's
// texel, the reference's fiber there (or within a pixel: decoded points are
// micrometres off the raw ones), and unproject onto the picked fiber.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "gpu/submit.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/pick.h"
#include "render/gpu/tractogram_upload.h"
#include "render/reference_raster.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

class GpuPick : public test::GpuTest {};

// Distance (mm) from p to the polyline of fiber `f`.
double distanceToFiber(const Tractogram& t, uint32_t f, const Vec3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (uint64_t i = t.offsets[f]; i + 1 < t.offsets[f + 1]; ++i) {
    const float* a = t.point(i);
    const float* b = t.point(i + 1);
    double ab[3], ap[3], ab2 = 0, t0 = 0;
    for (int k = 0; k < 3; ++k) {
      ab[k] = double(b[k]) - a[k];
      ap[k] = p[k] - a[k];
      ab2 += ab[k] * ab[k];
      t0 += ab[k] * ap[k];
    }
    t0 = ab2 > 0 ? std::clamp(t0 / ab2, 0.0, 1.0) : 0.0;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (ap[k] - t0 * ab[k]) * (ap[k] - t0 * ab[k]);
    best = std::min(best, std::sqrt(d2));
  }
  return best;
}

TEST_F(GpuPick, pickedTexelsMatchTheGBufferTheReferenceAndTheFiberInTheWorld) {
  const Tractogram fibers = test::renderPhantom(300, 11);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  constexpr uint32_t kWidth = 160, kHeight = 120;
  const Camera camera = orbitCamera(tractogramBounds(fibers), 125, 20, kWidth, kHeight, 0.6);
  FrameRenderer renderer(context(), kWidth, kHeight);
  RenderSettings settings;
  settings.line_width_px = 2.0f;
  renderer.render(camera, settings, GpuScene{&upload.dataset});
  const auto texels = downloadGBuffer(context(), renderer.targets());
  const ReferenceFrame reference = rasterizeReference(fibers, camera, settings.line_width_px);

  // Millimetres per pixel at a depth: the picked point lies within a few
  // pixels' footprint of the fiber's polyline (the line is 2 px wide).
  const double px_per_mm_at_1mm = kHeight / (2 * std::tan(camera.fov_y_deg * M_PI / 360));
  std::mt19937 rng(5);
  int hits = 0, misses = 0, reference_agrees = 0;
  for (int attempt = 0; attempt < 400 && (hits < 40 || misses < 10); ++attempt) {
    const uint32_t x = rng() % kWidth, y = rng() % kHeight;
    const shader::GBufferTexel& texel = texels[size_t(y) * kWidth + x];
    const bool covered = texel.fiber != shader::kNoFiberId;
    if (covered ? hits >= 40 : misses >= 10) continue;
    SCOPED_TRACE("pixel " + std::to_string(x) + ", " + std::to_string(y));
    const PickResult pick = pickFiber(context(), renderer.targets(), x, y);
    ASSERT_EQ(pick.hit, covered);
    if (!covered) {
      ++misses;
      continue;
    }
    ++hits;
    EXPECT_EQ(pick.fiber, texel.fiber);
    EXPECT_EQ(pick.segment, texel.segment);
    EXPECT_EQ(pick.depth, texel.depth);
    ASSERT_LT(pick.fiber, fibers.streamlineCount());
    // The reference draws the same fiber at the pixel or its neighbours.
    bool near_reference = false;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int px = int(x) + dx, py = int(y) + dy;
        if (px >= 0 && py >= 0 && px < int(kWidth) && py < int(kHeight))
          near_reference |= reference.fiber[reference.index(px, py)] == pick.fiber;
      }
    reference_agrees += near_reference;
    // The unprojected point lies on the picked fiber (within 2 px at its depth).
    const std::optional<Vec3d> world = unprojectPixel(camera, x, y, pick.depth);
    ASSERT_TRUE(world.has_value());
    const Vec3d eye_to = {(*world)[0] - camera.eye[0], (*world)[1] - camera.eye[1], (*world)[2] - camera.eye[2]};
    const double distance = std::sqrt(eye_to[0] * eye_to[0] + eye_to[1] * eye_to[1] + eye_to[2] * eye_to[2]);
    const double mm_per_px = distance / px_per_mm_at_1mm;
    EXPECT_LT(distanceToFiber(fibers, pick.fiber, *world), 2.0 * mm_per_px);
  }
  EXPECT_EQ(hits, 40);
  EXPECT_EQ(misses, 10);
  EXPECT_GE(reference_agrees, 38) << "of " << hits;
}

TEST_F(GpuPick, backgroundAndOutOfRangePixelsAreNoHit) {
  const Tractogram fibers = test::renderPhantom(50, 3);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  constexpr uint32_t kSize = 64;
  // Far away: the phantom covers the middle, the corners are background.
  const Camera camera = orbitCamera(tractogramBounds(fibers), 30, 10, kSize, kSize, 3.0);
  FrameRenderer renderer(context(), kSize, kSize);
  renderer.render(camera, RenderSettings{}, GpuScene{&upload.dataset});
  const auto texels = downloadGBuffer(context(), renderer.targets());
  ASSERT_EQ(texels[0].fiber, shader::kNoFiberId);
  EXPECT_FALSE(pickFiber(context(), renderer.targets(), 0, 0).hit);
  for (auto [x, y] : {std::pair{kSize, 0u}, std::pair{0u, kSize}, std::pair{kSize, kSize},
                      std::pair{0xFFFFFFFFu, 0xFFFFFFFFu}, std::pair{0u, 0xFFFFFFFFu}}) {
    const PickResult pick = pickFiber(context(), renderer.targets(), x, y);
    EXPECT_FALSE(pick.hit) << x << ", " << y;
    EXPECT_EQ(pick.depth, 1.0f);
  }
  // A covered pixel in the middle still hits after the no-hit fills (the
  // read-back buffer is not stale).
  size_t covered = texels.size();
  for (size_t i = 0; i < texels.size(); ++i)
    if (texels[i].fiber != shader::kNoFiberId) covered = i;
  ASSERT_LT(covered, texels.size());
  const PickResult pick = pickFiber(context(), renderer.targets(), uint32_t(covered % kSize), uint32_t(covered / kSize));
  EXPECT_TRUE(pick.hit);
  EXPECT_EQ(pick.fiber, texels[covered].fiber);
}

TEST_F(GpuPick, recordedReadbackIntoAReusedBufferAndBadBuffersAreRejected) {
  const Tractogram fibers = test::renderPhantom(50, 4);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  constexpr uint32_t kSize = 48;
  const Camera camera = orbitCamera(tractogramBounds(fibers), 0, 0, kSize, kSize, 0.8);
  FrameRenderer renderer(context(), kSize, kSize);
  renderer.render(camera, RenderSettings{}, GpuScene{&upload.dataset});
  const auto texels = downloadGBuffer(context(), renderer.targets());
  gpu::Buffer& pick_buffer = buffer(kPickBufferBytes, gpu::MemoryUse::Readback);
  for (uint32_t i = 0; i < kSize * kSize; i += 97) {
    const uint32_t x = i % kSize, y = i / kSize;
    gpu::submitOnce(context(), [&](VkCommandBuffer cmd) { recordPickReadback(cmd, renderer.targets(), x, y, pick_buffer); });
    const PickResult pick = readPick(context(), pick_buffer);
    EXPECT_EQ(pick.hit, texels[i].fiber != shader::kNoFiberId) << i;
    if (pick.hit) {
      EXPECT_EQ(pick.fiber, texels[i].fiber) << i;
    }
  }
  gpu::Buffer& device_only = buffer(kPickBufferBytes, gpu::MemoryUse::DeviceLocal);
  EXPECT_THROW(gpu::submitOnce(context(),
                               [&](VkCommandBuffer cmd) { recordPickReadback(cmd, renderer.targets(), 0, 0, device_only); }),
               Error);
}

TEST(PickUnproject, unprojectInvertsTheProjectionAtPixelCentres) {
  const Bounds box = {{-50, -60, -40}, {55, 70, 45}};
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 200; ++i) {
    const Camera camera = orbitCamera(box, 360 * u(rng), 180 * u(rng) - 90, 50 + rng() % 400, 50 + rng() % 400,
                                      0.3 + 2 * u(rng), 10 + 80 * u(rng));
    const uint32_t px = rng() % camera.width, py = rng() % camera.height;
    const double depth = u(rng) * 0.999;
    const std::optional<Vec3d> world = unprojectPixel(camera, px, py, depth);
    ASSERT_TRUE(world.has_value());
    const std::array<double, 16> m = viewProjectionD(camera);
    double c[4];
    for (int r = 0; r < 4; ++r) c[r] = m[r] * (*world)[0] + m[4 + r] * (*world)[1] + m[8 + r] * (*world)[2] + m[12 + r];
    EXPECT_NEAR((c[0] / c[3] + 1) * camera.width / 2, px + 0.5, 1e-6);
    EXPECT_NEAR((c[1] / c[3] + 1) * camera.height / 2, py + 0.5, 1e-6);
    EXPECT_NEAR(c[2] / c[3], depth, 1e-9);
  }
  const Camera camera = orbitCamera(box, 10, 10, 64, 64);
  EXPECT_FALSE(unprojectPixel(camera, 3, 3, 1.0).has_value());  // background depth
  EXPECT_FALSE(unprojectPixel(camera, 3, 3, -0.5).has_value());
}

}  // namespace
}  // namespace fibscope
