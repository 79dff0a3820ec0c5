// FXAA (shaders/fxaa.comp through recordFxaa) on hand-made RGBA8 images:
// flat and gently varying regions pass through bit for bit, and a hard,
// aliased edge moves towards its true (box-filtered) coverage.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "gpu/submit.h"
#include "gpu_test_context.h"
#include "render/gpu/shading_stages.h"

namespace fibscope {
namespace {

constexpr uint32_t kSize = 64;

class GpuFxaa : public test::GpuTest {
 protected:
  std::vector<uint32_t> fxaa(const std::vector<uint32_t>& image) {
    FxaaPass pass = createFxaaPass(context());
    gpu::Buffer in, out;
    std::vector<uint32_t> result(image.size());
    try {
      in = gpu::createBuffer(context(), image.size() * 4, gpu::MemoryUse::DeviceLocal);
      out = gpu::createBuffer(context(), image.size() * 4, gpu::MemoryUse::DeviceLocal);
      gpu::uploadToBuffer(context(), in, image.data(), image.size() * 4);
      gpu::submitOnce(context(), [&](VkCommandBuffer cmd) { recordFxaa(cmd, pass, in, out, kSize, kSize); });
      gpu::downloadFromBuffer(context(), out, result.data(), result.size() * 4);
    } catch (...) {
      gpu::destroyBuffer(context(), in);
      gpu::destroyBuffer(context(), out);
      destroyFxaaPass(context(), pass);
      throw;
    }
    gpu::destroyBuffer(context(), in);
    gpu::destroyBuffer(context(), out);
    destroyFxaaPass(context(), pass);
    return result;
  }
};

uint32_t grey(int v) { return uint32_t(v) * 0x010101u | 0xFF000000u; }
int red(uint32_t c) { return int(c & 255u); }

// White where inside(x, y) holds at the pixel centre, black elsewhere, and
// the exact coverage of each pixel by 16 x 16 supersampling.
struct EdgeImage {
  std::vector<uint32_t> aliased;
  std::vector<double> coverage;
};
EdgeImage edgeImage(const std::function<bool(double, double)>& inside) {
  EdgeImage e{std::vector<uint32_t>(kSize * kSize), std::vector<double>(kSize * kSize)};
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      e.aliased[y * kSize + x] = grey(inside(x + 0.5, y + 0.5) ? 255 : 0);
      int hits = 0;
      for (int sy = 0; sy < 16; ++sy)
        for (int sx = 0; sx < 16; ++sx) hits += inside(x + (sx + 0.5) / 16, y + (sy + 0.5) / 16);
      e.coverage[y * kSize + x] = hits / 256.0;
    }
  return e;
}

double coverageError(const std::vector<uint32_t>& image, const std::vector<double>& coverage) {
  double sum = 0;
  for (size_t i = 0; i < image.size(); ++i) sum += std::fabs(red(image[i]) - 255.0 * coverage[i]);
  return sum;
}

TEST_F(GpuFxaa, flatAndGentleRegionsAreUnchanged) {
  std::vector<uint32_t> flat(kSize * kSize, 0xFF4080C0u);
  EXPECT_EQ(fxaa(flat), flat);
  // A gradient of one grey level per pixel is far below the edge threshold.
  std::vector<uint32_t> ramp(kSize * kSize);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) ramp[y * kSize + x] = grey(int(x + y));
  EXPECT_EQ(fxaa(ramp), ramp);
}

TEST_F(GpuFxaa, aHardShallowEdgeMovesTowardsItsCoverage) {
  // Shallow and steep edges (slopes 1/3 and 3): the horizontal and the
  // vertical branch of the edge search.
  for (bool steep : {false, true}) {
    SCOPED_TRACE(steep ? "steep" : "shallow");
    const EdgeImage e = edgeImage([&](double x, double y) {
      return steep ? x < 20.0 + y / 3.0 : y < 20.0 + x / 3.0;
    });
    const std::vector<uint32_t> smooth = fxaa(e.aliased);
    const double before = coverageError(e.aliased, e.coverage), after = coverageError(smooth, e.coverage);
    std::printf("%s edge: |image - coverage| summed %.0f aliased, %.0f after FXAA\n", steep ? "steep" : "shallow",
                before, after);
    EXPECT_LT(after, 0.7 * before);
    size_t intermediate = 0;
    for (uint32_t y = 0; y < kSize; ++y)
      for (uint32_t x = 0; x < kSize; ++x) {
        const size_t i = y * kSize + x;
        const int v = red(smooth[i]);
        intermediate += v > 20 && v < 235;
        // Pixels 3 or more from the edge keep their value exactly.
        const double d = steep ? std::fabs(x + 0.5 - (20.0 + (y + 0.5) / 3.0)) * 3.0 / std::sqrt(10.0)
                               : std::fabs(y + 0.5 - (20.0 + (x + 0.5) / 3.0)) * 3.0 / std::sqrt(10.0);
        if (d >= 3.0) {
          ASSERT_EQ(smooth[i], e.aliased[i]) << "pixel " << x << ", " << y;
        }
        ASSERT_EQ(smooth[i] >> 24, 255u);
      }
    // Along the 64-pixel edge, most stair steps gain intermediate shades.
    EXPECT_GE(intermediate, 40u);
  }
}

TEST_F(GpuFxaa, aLoneBrightPixelIsSoftened) {
  std::vector<uint32_t> image(kSize * kSize, grey(0));
  image[20 * kSize + 20] = grey(255);
  const std::vector<uint32_t> smooth = fxaa(image);
  // Unlike its whole neighbourhood (sub-pixel term 1): blended by subpix
  // 0.75 towards a black neighbour, 255 * 0.25 = 63.75.
  EXPECT_EQ(red(smooth[20 * kSize + 20]), 64);
  EXPECT_EQ(smooth[40 * kSize + 40], grey(0));
}

}  // namespace
}  // namespace fibscope
