// Post effects (shaders/post_effects.comp through recordPostEffects, and the
// post stage in a frame; formulas in shaders/shared/post_push.h) against a
// CPU implementation of the formulas written here in double precision:
// flattening, contrast, brightness, saturation (luminance 0.2125, 0.7154,
// 0.0721) and sharpening by the 3x3 kernel, each alone and all together,
// on random colour images with hard edges, every channel within 1/255.
// The borders: a neighbour off the image reads the nearest pixel on it.
// And `fibscope render` with each flag against the plain render.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/submit.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/shading_stages.h"
#include "render/gpu/tractogram_upload.h"
#include "render/settings_table.h"
#include "test_support.h"

namespace fibscope {
namespace {

// An RGB image of doubles in [0, 1].
using Rgb = std::array<double, 3>;
struct Image {
  uint32_t width = 0, height = 0;
  std::vector<Rgb> px;
  const Rgb& at(int x, int y) const {
    x = std::clamp(x, 0, int(width) - 1);
    y = std::clamp(y, 0, int(height) - 1);
    return px[size_t(y) * width + size_t(x)];
  }
};

double clamp01(double v) { return std::min(1.0, std::max(0.0, v)); }

// FiberVisualizer section 12, one effect after the other, each clamped.
Rgb gradeReference(Rgb c, const RenderSettings& s) {
  for (double& v : c) {
    if (s.flatten_levels >= 2) v = std::round(v * (s.flatten_levels - 1)) / (s.flatten_levels - 1);
    v = clamp01((v - 0.5) * s.contrast + 0.5);
    v = clamp01(v + s.brightness);
  }
  const double luminance = 0.2125 * c[0] + 0.7154 * c[1] + 0.0721 * c[2];
  for (double& v : c) v = clamp01(luminance + s.saturation * (v - luminance));
  return c;
}

Image postReference(const Image& in, const RenderSettings& s) {
  Image graded = in;
  for (Rgb& c : graded.px) c = gradeReference(c, s);
  if (s.sharpen == 0.0f) return graded;
  Image out = graded;
  const double a = s.sharpen;
  for (int y = 0; y < int(in.height); ++y)
    for (int x = 0; x < int(in.width); ++x)
      for (int k = 0; k < 3; ++k)
        out.px[size_t(y) * in.width + x][k] =
            clamp01((1 + 4 * a) * graded.at(x, y)[k] -
                    a * (graded.at(x - 1, y)[k] + graded.at(x + 1, y)[k] + graded.at(x, y - 1)[k] + graded.at(x, y + 1)[k]));
  return out;
}

std::vector<uint32_t> pack(const Image& image) {
  std::vector<uint32_t> out;
  for (const Rgb& c : image.px) {
    uint32_t v = 0xFF000000u;
    for (int k = 0; k < 3; ++k) v |= uint32_t(std::lround(clamp01(c[k]) * 255)) << (8 * k);
    out.push_back(v);
  }
  return out;
}

Image unpack(const std::vector<uint32_t>& rgba, uint32_t width, uint32_t height) {
  Image image{width, height, {}};
  for (uint32_t v : rgba) image.px.push_back({(v & 255u) / 255.0, ((v >> 8) & 255u) / 255.0, ((v >> 16) & 255u) / 255.0});
  return image;
}

// Random pixels, with a band of black and white squares (hard edges) and a
// saturated colour block, at a size that is no multiple of the 8 x 8
// workgroups.
Image syntheticImage(uint32_t width, uint32_t height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  Image image{width, height, {}};
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      Rgb c{byte(rng) / 255.0, byte(rng) / 255.0, byte(rng) / 255.0};
      if (y < 12) c = ((x / 3 + y / 3) % 2) ? Rgb{1, 1, 1} : Rgb{0, 0, 0};
      if (y >= 12 && y < 18 && x < 20) c = {1.0, 40 / 255.0, 0};
      image.px.push_back(c);
    }
  return image;
}

// The largest channel difference in 1/255 steps, and that alpha is 255.
int largestDifference(const std::vector<uint32_t>& got, const std::vector<uint32_t>& expected) {
  int worst = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    if ((got[i] >> 24) != 255u) return 1000;
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(int((got[i] >> (8 * k)) & 255u) - int((expected[i] >> (8 * k)) & 255u)));
  }
  return worst;
}

// The cases: each effect on its own (two values where the sign matters),
// then all five at once.
std::vector<std::pair<std::string, RenderSettings>> effectCases() {
  std::vector<std::pair<std::string, RenderSettings>> cases;
  auto add = [&](std::string name, auto edit) {
    RenderSettings s;
    edit(s);
    cases.emplace_back(std::move(name), s);
  };
  add("flatten 2", [](RenderSettings& s) { s.flatten_levels = 2; });
  add("flatten 5", [](RenderSettings& s) { s.flatten_levels = 5; });
  add("contrast 1.8", [](RenderSettings& s) { s.contrast = 1.8f; });
  add("contrast 0.4", [](RenderSettings& s) { s.contrast = 0.4f; });
  add("brightness 0.2", [](RenderSettings& s) { s.brightness = 0.2f; });
  add("brightness -0.3", [](RenderSettings& s) { s.brightness = -0.3f; });
  add("saturation 0", [](RenderSettings& s) { s.saturation = 0.0f; });
  add("saturation 1.7", [](RenderSettings& s) { s.saturation = 1.7f; });
  add("sharpen 0.6", [](RenderSettings& s) { s.sharpen = 0.6f; });
  add("sharpen 2", [](RenderSettings& s) { s.sharpen = 2.0f; });
  add("all", [](RenderSettings& s) {
    s.flatten_levels = 9;
    s.contrast = 1.3f;
    s.brightness = -0.05f;
    s.saturation = 0.6f;
    s.sharpen = 0.5f;
  });
  return cases;
}

class GpuPostEffects : public test::GpuTest {
 protected:
  std::vector<uint32_t> post(const std::vector<uint32_t>& image, uint32_t width, uint32_t height,
                             const RenderSettings& s) {
    PostPass pass = createPostPass(context());
    gpu::Buffer in, out;
    std::vector<uint32_t> result(image.size());
    try {
      in = gpu::createBuffer(context(), image.size() * 4, gpu::MemoryUse::DeviceLocal);
      out = gpu::createBuffer(context(), image.size() * 4, gpu::MemoryUse::DeviceLocal);
      gpu::uploadToBuffer(context(), in, image.data(), image.size() * 4);
      gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
        recordPostEffects(cmd, pass, in, out, width, height, s);
      });
      gpu::downloadFromBuffer(context(), out, result.data(), result.size() * 4);
    } catch (...) {
      gpu::destroyBuffer(context(), in);
      gpu::destroyBuffer(context(), out);
      destroyPostPass(context(), pass);
      throw;
    }
    gpu::destroyBuffer(context(), in);
    gpu::destroyBuffer(context(), out);
    destroyPostPass(context(), pass);
    return result;
  }
};

TEST_F(GpuPostEffects, eachEffectAndAllTogetherMatchTheFormulasWithinOneLevel) {
  constexpr uint32_t kWidth = 45, kHeight = 29;
  const Image image = syntheticImage(kWidth, kHeight, 7);
  const std::vector<uint32_t> input = pack(image);
  for (const auto& [name, s] : effectCases()) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(postEffectsRun(s));
    const std::vector<uint32_t> got = post(input, kWidth, kHeight, s);
    const std::vector<uint32_t> expected = pack(postReference(image, s));
    EXPECT_LE(largestDifference(got, expected), 1);
    // Every case changes the image somewhere.
    EXPECT_NE(got, input);
  }
}

TEST_F(GpuPostEffects, sharpeningAtTheBordersReadsTheNearestPixel) {
  // A bright column at x = 0 and a bright row at the bottom: with the
  // border clamped, the column's own pixels see themselves as their left
  // neighbour, so their value is (1 + 4a) v - a (v + v + right + ...).
  constexpr uint32_t kWidth = 9, kHeight = 9;
  constexpr double kDark = 64 / 255.0, kBright = 192 / 255.0;  // exact 8-bit values
  Image image{kWidth, kHeight, std::vector<Rgb>(kWidth * kHeight, Rgb{kDark, kDark, kDark})};
  for (uint32_t y = 0; y < kHeight; ++y) image.px[y * kWidth] = {kBright, kBright, kBright};
  for (uint32_t x = 0; x < kWidth; ++x) image.px[(kHeight - 1) * kWidth + x] = {0.6, 0.5, 0.4};
  RenderSettings s;
  s.sharpen = 0.25f;
  const std::vector<uint32_t> got = post(pack(image), kWidth, kHeight, s);
  EXPECT_LE(largestDifference(got, pack(postReference(image, s))), 1);
  // (x, y) = (0, 4): 2 v - 0.25 (v + v + v + d) with v = 192, d = 64 (the
  // clamped left neighbour is the pixel itself, above and below are the
  // column): 224 exactly.
  EXPECT_EQ(int(got[4 * kWidth] & 255u), 2 * 192 - (3 * 192 + 64) / 4);
}

TEST_F(GpuPostEffects, neutralValuesLeaveEveryPixelAsItWas) {
  constexpr uint32_t kWidth = 37, kHeight = 21;
  const std::vector<uint32_t> input = pack(syntheticImage(kWidth, kHeight, 11));
  RenderSettings s;  // every effect neutral: the pass itself is the identity
  EXPECT_FALSE(postEffectsRun(s));
  EXPECT_EQ(post(input, kWidth, kHeight, s), input);
  s.flatten_levels = 256;  // 256 levels are the 8-bit values themselves
  EXPECT_TRUE(postEffectsRun(s));
  EXPECT_EQ(post(input, kWidth, kHeight, s), input);
  s.flatten_levels = 1;  // one level: off
  EXPECT_FALSE(postEffectsRun(s));
  EXPECT_EQ(post(input, kWidth, kHeight, s), input);
}

// In a frame: shade's image goes through post and then FXAA (both on, the
// buffers ping-pong through the frame's colour); the frame equals the two
// passes run by hand on the plain frame, and the post pass is timed only
// when some effect is on.
TEST_F(GpuPostEffects, aFrameRunsPostAfterShadingAndBeforeFxaaOnlyWhenAnEffectIsOn) {
  const Tractogram fibers = test::renderPhantom(200, 3);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  constexpr uint32_t kFrame = 96;
  FrameRenderer renderer(context(), kFrame, kFrame);
  const Camera camera = standardView(tractogramBounds(fibers), StandardView::Coronal, kFrame, kFrame);
  const GpuScene scene{&upload.dataset};
  RenderSettings plain;
  plain.culling = CullingMode::None;
  auto names = [](const FrameStats& stats) {
    std::string all;
    for (const PassTiming& p : stats.passes) all += p.name + ";";
    return all;
  };
  const FrameStats plain_stats = renderer.render(camera, plain, scene);
  EXPECT_EQ(names(plain_stats).find("post"), std::string::npos) << names(plain_stats);
  const std::vector<uint8_t> shaded_bytes = downloadColor(context(), renderer.targets());
  std::vector<uint32_t> shaded(kFrame * kFrame);
  std::memcpy(shaded.data(), shaded_bytes.data(), shaded_bytes.size());

  RenderSettings effects = plain;
  effects.contrast = 1.5f;
  effects.saturation = 0.5f;
  effects.sharpen = 0.4f;
  for (bool fxaa : {false, true}) {
    SCOPED_TRACE(fxaa ? "with FXAA" : "without FXAA");
    effects.fxaa = fxaa;
    const FrameStats stats = renderer.render(camera, effects, scene);
    const std::string order = names(stats);
    ASSERT_NE(order.find("shade;post;"), std::string::npos) << order;
    if (fxaa) EXPECT_NE(order.find("post;fxaa;"), std::string::npos) << order;
    const std::vector<uint8_t> bytes = downloadColor(context(), renderer.targets());
    std::vector<uint32_t> frame(kFrame * kFrame);
    std::memcpy(frame.data(), bytes.data(), bytes.size());
    std::vector<uint32_t> expected = post(shaded, kFrame, kFrame, effects);
    EXPECT_NE(expected, shaded);
    if (fxaa) {
      FxaaPass pass = createFxaaPass(context());
      gpu::Buffer in = gpu::createBuffer(context(), expected.size() * 4, gpu::MemoryUse::DeviceLocal);
      gpu::Buffer out = gpu::createBuffer(context(), expected.size() * 4, gpu::MemoryUse::DeviceLocal);
      gpu::uploadToBuffer(context(), in, expected.data(), expected.size() * 4);
      gpu::submitOnce(context(), [&](VkCommandBuffer cmd) { recordFxaa(cmd, pass, in, out, kFrame, kFrame); });
      gpu::downloadFromBuffer(context(), out, expected.data(), expected.size() * 4);
      gpu::destroyBuffer(context(), in);
      gpu::destroyBuffer(context(), out);
      destroyFxaaPass(context(), pass);
    }
    EXPECT_EQ(frame, expected);
  }
}

TEST(PostEffectsSettings, areInTheTableOffByDefaultWithTheirRanges) {
  const RenderSettings defaults;
  EXPECT_FALSE(postEffectsRun(defaults));
  for (const char* name : {"flatten", "contrast", "brightness", "saturation", "sharpen"}) {
    SCOPED_TRACE(name);
    const SettingInfo* info = findSetting(name);
    ASSERT_NE(info, nullptr);
    EXPECT_TRUE(info->group.empty());  // the render settings panel
    RenderSettings s;
    setSetting(s, *info, settingText(defaults, *info), "test");
    EXPECT_FALSE(postEffectsRun(s));
    setSetting(s, *info, info->kind == SettingKind::Integer ? "3" : "0.5", "test");
    EXPECT_TRUE(postEffectsRun(s));
    EXPECT_THROW(setSetting(s, *info, "300", "test"), Error);
    EXPECT_THROW(setSetting(s, *info, "nan", "test"), Error);
  }
  RenderSettings s;
  EXPECT_THROW(setSetting(s, *findSetting("flatten"), "2.5", "test"), Error);
  EXPECT_THROW(setSetting(s, *findSetting("flatten"), "257", "test"), Error);
  EXPECT_THROW(setSetting(s, *findSetting("brightness"), "-1.5", "test"), Error);
  s.contrast = -1.0f;
  EXPECT_THROW(validateRenderSettings(s), Error);
}

// `fibscope render` with each flag: the PNG is the plain render's with the
// effect applied by the CPU formulas (within 1/255; the orientation labels,
// stamped after the effects, are off), and equal to it at the neutral value.
class GpuCliPostEffects : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runFibscope("gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::Png render(const std::string& flags, const std::string& name) {
    const std::string png = dir_.file(name + ".png");
    const auto r = test::runFibscope(
        "render --validate --phantom-streamlines 300 --size 96x72 --view coronal --no-orientation-labels "
        "--background 0.1,0.15,0.2 -o " + png + " " + flags);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return test::readOurPng(png);
  }
  test::TempDir dir_;
};

Image imageOf(const test::Png& png) {
  Image image{png.width, png.height, {}};
  for (size_t i = 0; i + 3 < png.rgba.size(); i += 4)
    image.px.push_back({png.rgba[i] / 255.0, png.rgba[i + 1] / 255.0, png.rgba[i + 2] / 255.0});
  return image;
}

std::vector<uint32_t> packedOf(const test::Png& png) {
  std::vector<uint32_t> out(png.rgba.size() / 4);
  std::memcpy(out.data(), png.rgba.data(), out.size() * 4);
  return out;
}

TEST_F(GpuCliPostEffects, eachFlagAppliesItsFormulaToThePlainRenderAndItsNeutralValueChangesNothing) {
  const test::Png plain = render("", "plain");
  ASSERT_EQ(plain.width, 96u);
  struct Case {
    std::string flag, value, neutral;
    void (*apply)(RenderSettings&);
  };
  const std::vector<Case> cases = {
      {"flatten", "4", "256", [](RenderSettings& s) { s.flatten_levels = 4; }},
      {"contrast", "1.6", "1", [](RenderSettings& s) { s.contrast = 1.6f; }},
      {"brightness", "0.2", "0", [](RenderSettings& s) { s.brightness = 0.2f; }},
      {"saturation", "0.3", "1", [](RenderSettings& s) { s.saturation = 0.3f; }},
      {"sharpen", "0.8", "0", [](RenderSettings& s) { s.sharpen = 0.8f; }},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.flag);
    const test::Png on = render("--" + c.flag + " " + c.value, c.flag);
    RenderSettings s;
    c.apply(s);
    ASSERT_EQ(on.rgba.size(), plain.rgba.size());
    EXPECT_NE(on.rgba, plain.rgba);
    EXPECT_LE(largestDifference(packedOf(on), pack(postReference(imageOf(plain), s))), 1);
    EXPECT_EQ(render("--" + c.flag + " " + c.neutral, c.flag + "_neutral").rgba, plain.rgba);
  }
  const auto bad = test::runFibscope("render --size 32x32 --contrast 9 -o " + dir_.file("bad.png"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("contrast"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace fibscope
