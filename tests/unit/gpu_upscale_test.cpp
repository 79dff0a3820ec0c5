// The upscale pass (shaders/upscale_color.comp through recordUpscale) that
// stretches the viewer's half-resolution coarse frames over the window:
// against a CPU bilinear filter with the same pixel-centre mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "gpu/submit.h"
#include "gpu_test_context.h"
#include "render/gpu/upscale_pass.h"

namespace fibscope {
namespace {

class GpuUpscale : public test::GpuTest {
 protected:
  std::vector<uint32_t> upscale(const std::vector<uint32_t>& image, uint32_t sw, uint32_t sh, uint32_t dw,
                                uint32_t dh) {
    UpscalePass pass = createUpscalePass(context());
    gpu::Buffer src, dst;
    std::vector<uint32_t> result(size_t(dw) * dh);
    try {
      src = gpu::createBuffer(context(), image.size() * 4, gpu::MemoryUse::DeviceLocal);
      dst = gpu::createBuffer(context(), result.size() * 4, gpu::MemoryUse::DeviceLocal);
      gpu::uploadToBuffer(context(), src, image.data(), image.size() * 4);
      gpu::submitOnce(context(), [&](VkCommandBuffer cmd) { recordUpscale(cmd, pass, src, sw, sh, dst, dw, dh); });
      gpu::downloadFromBuffer(context(), dst, result.data(), result.size() * 4);
    } catch (...) {
      gpu::destroyBuffer(context(), src);
      gpu::destroyBuffer(context(), dst);
      destroyUpscalePass(context(), pass);
      throw;
    }
    gpu::destroyBuffer(context(), src);
    gpu::destroyBuffer(context(), dst);
    destroyUpscalePass(context(), pass);
    return result;
  }
};

// The CPU reference: destination pixel centres mapped onto source pixel
// centres, clamp-to-edge bilinear per channel, rounded.
std::vector<uint32_t> referenceUpscale(const std::vector<uint32_t>& image, uint32_t sw, uint32_t sh, uint32_t dw,
                                       uint32_t dh) {
  auto channel = [&](int x, int y, int c) {
    x = std::clamp(x, 0, int(sw) - 1);
    y = std::clamp(y, 0, int(sh) - 1);
    return double((image[size_t(y) * sw + size_t(x)] >> (8 * c)) & 255u);
  };
  std::vector<uint32_t> out(size_t(dw) * dh);
  for (uint32_t y = 0; y < dh; ++y)
    for (uint32_t x = 0; x < dw; ++x) {
      const double sx = (x + 0.5) * sw / dw - 0.5, sy = (y + 0.5) * sh / dh - 0.5;
      const int qx = int(std::floor(sx)), qy = int(std::floor(sy));
      const double fx = sx - qx, fy = sy - qy;
      uint32_t packed = 0;
      for (int c = 0; c < 4; ++c) {
        const double top = channel(qx, qy, c) * (1 - fx) + channel(qx + 1, qy, c) * fx;
        const double bottom = channel(qx, qy + 1, c) * (1 - fx) + channel(qx + 1, qy + 1, c) * fx;
        packed |= uint32_t(std::clamp(std::floor(top * (1 - fy) + bottom * fy + 0.5), 0.0, 255.0)) << (8 * c);
      }
      out[size_t(y) * dw + x] = packed;
    }
  return out;
}

// Largest difference of one channel between two images.
int maxChannelDifference(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  int worst = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 4; ++c)
      worst = std::max(worst, std::abs(int((a[i] >> (8 * c)) & 255u) - int((b[i] >> (8 * c)) & 255u)));
  return worst;
}

TEST_F(GpuUpscale, halfResolutionFramesStretchLikeABilinearFilter) {
  std::mt19937 rng(7);
  for (auto [sw, sh, dw, dh] : {std::array<uint32_t, 4>{20, 12, 40, 24}, {21, 13, 43, 27}, {5, 3, 64, 9}}) {
    std::vector<uint32_t> image(size_t(sw) * sh);
    for (uint32_t& v : image) v = rng();
    const std::vector<uint32_t> gpu = upscale(image, sw, sh, dw, dh);
    // Float rounding on the GPU: at most one step of a channel.
    EXPECT_LE(maxChannelDifference(gpu, referenceUpscale(image, sw, sh, dw, dh)), 1)
        << sw << "x" << sh << " -> " << dw << "x" << dh;
  }
}

TEST_F(GpuUpscale, flatImagesStayFlatAndTheSameSizeIsACopy) {
  std::vector<uint32_t> flat(8 * 6, 0xFF4080C0u);
  EXPECT_EQ(upscale(flat, 8, 6, 16, 12), std::vector<uint32_t>(16 * 12, 0xFF4080C0u));
  std::vector<uint32_t> image(9 * 7);
  std::mt19937 rng(3);
  for (uint32_t& v : image) v = rng();
  EXPECT_EQ(upscale(image, 9, 7, 9, 7), image);
}

TEST_F(GpuUpscale, emptySizesAndShortBuffersAreErrors) {
  UpscalePass pass = createUpscalePass(context());
  gpu::Buffer small = gpu::createBuffer(context(), 16, gpu::MemoryUse::DeviceLocal);
  VkCommandBuffer cmd = VK_NULL_HANDLE;  // never reached: the checks come first
  EXPECT_THROW(recordUpscale(cmd, pass, small, 0, 2, small, 2, 2), Error);
  EXPECT_THROW(recordUpscale(cmd, pass, small, 2, 2, small, 4, 4), Error);
  gpu::destroyBuffer(context(), small);
  destroyUpscalePass(context(), pass);
}

}  // namespace
}  // namespace fibscope
