// The shading passes (src/render/gpu_shade_pass.h) on hand-made G-buffers,
// checked against CPU computations of the same formulas written
// independently of the shaders (world position from the inverse of the
// double-precision view-projection, light from the camera's look-at frame),
// and on whole phantom frames through the FrameRenderer. Validation layers
// on (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include "core/error.h"
#include "gpu/submit.h"
#include "gpu_test_context.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/camera.h"
#include "render/gpu_frame_renderer.h"
#include "render/gpu_shade_pass.h"
#include "render/gpu_tractogram_upload.h"
#include "render/reference_raster.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "shared/shade_push.h"

namespace fibscope {
namespace {

using V3 = std::array<double, 3>;
using Rgb = std::array<double, 3>;

V3 sub(V3 a, V3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(V3 a, V3 b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
V3 normalized(V3 a) {
  const double l = std::sqrt(dot(a, a));
  return {a[0] / l, a[1] / l, a[2] / l};
}

// Octahedral mapping + packSnorm2x16, as the G-buffer stores tangents.
uint32_t packTangent(V3 t) {
  t = normalized(t);
  const double l1 = std::fabs(t[0]) + std::fabs(t[1]) + std::fabs(t[2]);
  double x = t[0] / l1, y = t[1] / l1;
  if (t[2] < 0) {
    const double ox = (1 - std::fabs(y)) * (x >= 0 ? 1 : -1);
    const double oy = (1 - std::fabs(x)) * (y >= 0 ? 1 : -1);
    x = ox;
    y = oy;
  }
  auto snorm = [](double v) { return uint32_t(uint16_t(int16_t(std::lround(std::clamp(v, -1.0, 1.0) * 32767.0)))); };
  return snorm(x) | (snorm(y) << 16);
}

// 4x4 inverse by Gauss-Jordan with partial pivoting (column-major in and out).
std::array<double, 16> inverse(const std::array<double, 16>& m) {
  double a[4][8];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      a[r][c] = m[4 * c + r];
      a[r][c + 4] = r == c ? 1 : 0;
    }
  for (int c = 0; c < 4; ++c) {
    int pivot = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::fabs(a[r][c]) > std::fabs(a[pivot][c])) pivot = r;
    std::swap(a[c], a[pivot]);
    const double d = a[c][c];
    for (double& v : a[c]) v /= d;
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      const double f = a[r][c];
      for (int k = 0; k < 8; ++k) a[r][k] -= f * a[c][k];
    }
  }
  std::array<double, 16> out{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[4 * c + r] = a[r][c + 4];
  return out;
}

// Clip depth z/w of a point at view distance `z` mm (camera.cpp's projection).
float clipDepth(const Camera& camera, double z) {
  const double n = camera.near_mm, f = camera.far_mm;
  return float(f * (z - n) / ((f - n) * z));
}

std::array<uint8_t, 4> quantize(Rgb c) {
  std::array<uint8_t, 4> out{};
  for (int k = 0; k < 3; ++k) out[k] = uint8_t(std::clamp(c[k], 0.0, 1.0) * 255.0 + 0.5);
  out[3] = 255;
  return out;
}

// The lowbias32 hash and the HSV colour the per-fiber mode promises.
Rgb expectedFiberColor(uint32_t fiber) {
  uint32_t x = fiber;
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  const double hue = double(x & 0xFFFFu) / 65536.0;
  const double sat = 0.45 + 0.4 * double((x >> 16) & 0xFFu) / 255.0;
  const double val = 0.75 + 0.25 * double(x >> 24) / 255.0;
  // Classic sector form of HSV -> RGB.
  const double h6 = hue * 6.0;
  const int sector = int(std::floor(h6)) % 6;
  const double f = h6 - std::floor(h6);
  const double p = val * (1 - sat), q = val * (1 - sat * f), t = val * (1 - sat * (1 - f));
  switch (sector) {
    case 0: return {val, t, p};
    case 1: return {q, val, p};
    case 2: return {p, val, t};
    case 3: return {p, q, val};
    case 4: return {t, p, val};
    default: return {val, p, q};
  }
}

struct Texel {
  uint32_t x, y;
  V3 tangent;
  double distance_mm;  // view distance
  uint32_t fiber;
};

// The colour the shading promises for one texel, computed on the CPU.
Rgb expectedColor(const Camera& camera, const RenderSettings& s, const Texel& t) {
  const V3 tangent = normalized(t.tangent);
  Rgb base{};
  switch (s.color) {
    case ColorMode::Solid: base = {s.solid_color[0], s.solid_color[1], s.solid_color[2]}; break;
    case ColorMode::Orientation:
      base = {std::fabs(tangent[0]), std::fabs(tangent[1]), std::fabs(tangent[2])};
      break;
    case ColorMode::PerFiber: base = expectedFiberColor(t.fiber); break;
    default: ADD_FAILURE() << "no reference for " << colorModeName(s.color); break;
  }
  if (s.lighting == Lighting::None) return base;
  // World position of the pixel centre at its depth, through the inverse
  // view-projection; V points from it to the eye.
  const auto inv = inverse(viewProjectionD(camera));
  const double ndc[4] = {(t.x + 0.5) / camera.width * 2 - 1, (t.y + 0.5) / camera.height * 2 - 1,
                         double(clipDepth(camera, t.distance_mm)), 1};
  double w[4] = {0, 0, 0, 0};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) w[r] += inv[4 * c + r] * ndc[c];
  const V3 world = {w[0] / w[3], w[1] / w[3], w[2] / w[3]};
  const V3 v = normalized(sub(camera.eye, world));
  // The light: view-space (kShadeLightView*) in the camera's look-at frame.
  const V3 back = normalized(sub(camera.eye, camera.target));
  const V3 right = normalized(cross(camera.up, back));
  const V3 up = cross(back, right);
  const V3 lv = normalized({shader::kShadeLightViewX, shader::kShadeLightViewY, shader::kShadeLightViewZ});
  const V3 l = {lv[0] * right[0] + lv[1] * up[0] + lv[2] * back[0], lv[0] * right[1] + lv[1] * up[1] + lv[2] * back[1],
                lv[0] * right[2] + lv[1] * up[2] + lv[2] * back[2]};
  const double lt = dot(l, tangent), vt = dot(v, tangent);
  const double diffuse = std::sqrt(std::max(0.0, 1 - lt * lt));
  const double specular =
      std::pow(std::max(0.0, diffuse * std::sqrt(std::max(0.0, 1 - vt * vt)) - lt * vt), s.light_shininess);
  Rgb c{};
  for (int k = 0; k < 3; ++k) c[k] = base[k] * (s.light_ambient + s.light_diffuse * diffuse) + s.light_specular * specular;
  return c;
}

class GpuShade : public test::GpuTest {
 protected:
  static constexpr uint32_t kSize = 32;

  Camera camera() const {
    Camera c;
    c.eye = {10, -20, 100};
    c.target = {0, 5, 0};
    c.up = {0, 1, 0};
    c.width = kSize;
    c.height = kSize;
    return c;
  }

  // Shades a G-buffer that is empty but for `texels` and returns RGBA8.
  std::vector<uint8_t> shade(const std::vector<Texel>& texels, const RenderSettings& settings) {
    std::vector<shader::GBufferTexel> gbuffer(kSize * kSize, {1.0f, shader::kNoFiberId, 0, 0});
    for (const Texel& t : texels)
      gbuffer[t.y * kSize + t.x] = {clipDepth(camera(), t.distance_mm), t.fiber, 0, packTangent(t.tangent)};
    GpuFrameTargets frame = createFrameTargets(context(), kSize, kSize);
    ShadePass pass{};
    std::vector<uint8_t> rgba;
    try {
      pass = createShadePass(context(), kSize, kSize);
      const shader::CameraBlock block = makeCameraBlock(camera(), 1.0f);
      gpu::uploadToBuffer(context(), frame.camera, &block, sizeof(block));
      gpu::uploadToBuffer(context(), frame.gbuffer, gbuffer.data(), gbuffer.size() * sizeof(gbuffer[0]));
      gpu::submitOnce(context(), [&](VkCommandBuffer cmd) { recordShade(cmd, pass, frame, settings, nullptr); });
      rgba = downloadColor(context(), frame);
    } catch (...) {
      destroyShadePass(context(), pass);
      destroyFrameTargets(context(), frame);
      throw;
    }
    destroyShadePass(context(), pass);
    destroyFrameTargets(context(), frame);
    return rgba;
  }

  static std::array<uint8_t, 4> pixel(const std::vector<uint8_t>& rgba, uint32_t x, uint32_t y) {
    const size_t i = 4 * (size_t(y) * kSize + x);
    return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
  }
  static double luminance(std::array<uint8_t, 4> p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

  static void expectNear(std::array<uint8_t, 4> got, std::array<uint8_t, 4> want, const char* what) {
    for (int k = 0; k < 4; ++k)
      EXPECT_LE(std::abs(int(got[k]) - int(want[k])), k == 3 ? 0 : 2)
          << what << ": channel " << k << " got " << int(got[k]) << " want " << int(want[k]);
  }
};

// A spread of tangents (axes, diagonals, ones facing the light and the eye)
// at pixels across the frame, distances 80-120 mm, distinct fibers.
std::vector<Texel> sampleTexels() {
  const V3 tangents[] = {{1, 0, 0},   {0, 1, 0},     {0, 0, 1},    {1, 1, 0},      {-1, 2, 0.5},
                         {0.3, -0.2, 0.93}, {-0.35, 0.45, 1}, {1, -1, 1}, {0.8, 0.1, -0.6}, {-0.2, -0.9, 0.4},
                         {0.45, 0.35, 0.1}, {0, -1, -1}};
  std::vector<Texel> texels;
  uint32_t i = 0;
  for (const V3& t : tangents) {
    // Every third column and row, so no two texels are neighbours.
    texels.push_back({(i * 7 + 1) % 30 + 1, (i * 5 + 2) % 30 + 1, t, 80.0 + 40.0 * i / 11.0, 100 + 37 * i});
    ++i;
  }
  return texels;
}

TEST_F(GpuShade, backgroundPixelsAreExactlyTheBackgroundColor) {
  RenderSettings s;
  s.background = {0.2f, 0.4f, 0.6f};
  const std::vector<Texel> texels = sampleTexels();
  for (ColorMode mode : {ColorMode::Solid, ColorMode::Orientation, ColorMode::PerFiber})
    for (bool ssao : {false, true}) {
      s.color = mode;
      s.ssao = ssao;
      const std::vector<uint8_t> rgba = shade(texels, s);
      const std::array<uint8_t, 4> bg = {uint8_t(0.2f * 255 + 0.5f), uint8_t(0.4f * 255 + 0.5f),
                                         uint8_t(0.6f * 255 + 0.5f), 255};
      size_t background = 0;
      for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x) {
          const bool drawn = std::any_of(texels.begin(), texels.end(), [&](const Texel& t) { return t.x == x && t.y == y; });
          if (drawn) continue;
          ++background;
          ASSERT_EQ(pixel(rgba, x, y), bg) << "pixel " << x << ", " << y;
        }
      EXPECT_EQ(background, kSize * kSize - texels.size());
    }
}

TEST_F(GpuShade, eachColorModeWithoutLightingMatchesTheCpu) {
  RenderSettings s;
  s.lighting = Lighting::None;
  s.ssao = false;
  s.solid_color = {0.9f, 0.3f, 0.15f};
  const std::vector<Texel> texels = sampleTexels();
  for (ColorMode mode : {ColorMode::Solid, ColorMode::Orientation, ColorMode::PerFiber}) {
    SCOPED_TRACE(std::string(colorModeName(mode)));
    s.color = mode;
    const std::vector<uint8_t> rgba = shade(texels, s);
    for (const Texel& t : texels) expectNear(pixel(rgba, t.x, t.y), quantize(expectedColor(camera(), s, t)), "texel");
  }
}

TEST_F(GpuShade, orientationColorIsTheReferenceConvention) {
  // shadeOrientation (reference_raster.h): |tangent| * 255 per channel.
  RenderSettings s;
  s.lighting = Lighting::None;
  s.ssao = false;
  s.color = ColorMode::Orientation;
  const std::vector<Texel> texels = sampleTexels();
  const std::vector<uint8_t> rgba = shade(texels, s);
  for (const Texel& t : texels) {
    const V3 n = normalized(t.tangent);
    const auto p = pixel(rgba, t.x, t.y);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(p[k], std::lround(std::fabs(n[k]) * 255.0), 1) << "channel " << k;
  }
}

TEST_F(GpuShade, perFiberColorsAreStableSpreadAndBright) {
  RenderSettings s;
  s.lighting = Lighting::None;
  s.ssao = false;
  s.color = ColorMode::PerFiber;
  std::vector<Texel> texels;
  for (uint32_t i = 0; i < 256; ++i) texels.push_back({i % 16 * 2, i / 16 * 2, {1, 0, 0}, 100, i});
  const std::vector<uint8_t> first = shade(texels, s);
  EXPECT_EQ(shade(texels, s), first) << "the same fibers give the same colours";
  std::set<std::array<uint8_t, 4>> distinct;
  std::array<int, 6> hue_sectors{};
  for (const Texel& t : texels) {
    const auto p = pixel(first, t.x, t.y);
    expectNear(p, quantize(expectedFiberColor(t.fiber)), "fiber colour");
    distinct.insert(p);
    const int brightest = std::max({p[0], p[1], p[2]});
    EXPECT_GE(brightest, int(0.75 * 255) - 1) << "fiber " << t.fiber << " is not dark";
    EXPECT_LT(std::min({p[0], p[1], p[2]}), brightest) << "fiber " << t.fiber << " is not grey";
    // Sector of the brightest and second channel (six hue sectors).
    const int max_k = int(std::max_element(p.begin(), p.begin() + 3) - p.begin());
    const int next = (max_k + 1) % 3, prev = (max_k + 2) % 3;
    ++hue_sectors[2 * max_k + (p[next] >= p[prev] ? 1 : 0)];
  }
  EXPECT_GE(distinct.size(), 250u);
  for (int k = 0; k < 6; ++k) EXPECT_GE(hue_sectors[k], 20) << "hue sector " << k;
}

TEST_F(GpuShade, illuminatedLinesMatchTheCpuFormulas) {
  RenderSettings s;
  s.lighting = Lighting::IlluminatedLines;
  s.ssao = false;
  const std::vector<Texel> texels = sampleTexels();
  for (ColorMode mode : {ColorMode::Solid, ColorMode::Orientation, ColorMode::PerFiber}) {
    SCOPED_TRACE(std::string(colorModeName(mode)));
    s.color = mode;
    const std::vector<uint8_t> rgba = shade(texels, s);
    for (const Texel& t : texels) expectNear(pixel(rgba, t.x, t.y), quantize(expectedColor(camera(), s, t)), "lit texel");
  }
  // Other coefficients and a low shininess, so the specular term is large.
  s.color = ColorMode::Solid;
  s.solid_color = {0.2f, 0.5f, 0.8f};
  s.light_ambient = 0.1f;
  s.light_diffuse = 0.6f;
  s.light_specular = 0.8f;
  s.light_shininess = 4.0f;
  const std::vector<uint8_t> rgba = shade(texels, s);
  for (const Texel& t : texels) expectNear(pixel(rgba, t.x, t.y), quantize(expectedColor(camera(), s, t)), "lit texel");
}

TEST_F(GpuShade, aLinePerpendicularToLightAndEyeGetsTheHighlight) {
  // T perpendicular to both L and V: diffuse 1, specular 1; T along the
  // view direction: diffuse and specular small.
  RenderSettings s;
  s.lighting = Lighting::IlluminatedLines;
  s.ssao = false;
  s.color = ColorMode::Solid;
  s.solid_color = {0.5f, 0.5f, 0.5f};
  const Camera c = camera();
  const V3 back = normalized(sub(c.eye, c.target));
  const V3 right = normalized(cross(c.up, back));
  const V3 up = cross(back, right);
  const V3 lv = normalized({shader::kShadeLightViewX, shader::kShadeLightViewY, shader::kShadeLightViewZ});
  const V3 l = {lv[0] * right[0] + lv[1] * up[0] + lv[2] * back[0], lv[0] * right[1] + lv[1] * up[1] + lv[2] * back[1],
                lv[0] * right[2] + lv[1] * up[2] + lv[2] * back[2]};
  const V3 across = normalized(cross(l, back));  // ~perpendicular to L and V at the centre
  const std::vector<Texel> texels = {{16, 16, across, 100, 1}, {20, 16, back, 100, 2}};
  const std::vector<uint8_t> rgba = shade(texels, s);
  const auto lit = pixel(rgba, 16, 16), dim = pixel(rgba, 20, 16);
  EXPECT_GT(lit[0], 0.5 * (s.light_ambient + s.light_diffuse) * 255 + 0.8 * s.light_specular * 255);
  EXPECT_LT(dim[0], lit[0] / 2);
  expectNear(lit, quantize(expectedColor(c, s, texels[0])), "highlight");
}

// A straight line of fiber 7 across the frame, receding in depth from 60 to
// 140 mm, with no other fiber.
std::vector<Texel> isolatedLine() {
  std::vector<Texel> texels;
  for (uint32_t x = 2; x < 30; ++x)
    for (uint32_t dy = 0; dy < 2; ++dy)
      texels.push_back({x, x / 2 + 5 + dy, {1, 0.5, -0.8}, 60.0 + 80.0 * (x - 2) / 27.0, 7});
  return texels;
}

TEST_F(GpuShade, ssaoLeavesAnIsolatedLineUntouched) {
  RenderSettings s;
  s.ssao_strength = 1.0f;
  s.ssao_radius_px = 10.0f;
  const std::vector<Texel> texels = isolatedLine();
  s.ssao = false;
  const std::vector<uint8_t> plain = shade(texels, s);
  s.ssao = true;
  EXPECT_EQ(shade(texels, s), plain);
}

// Fiber 1 at the centre (100 mm), a disc of fiber 2 around it at
// 100 - nearer_mm.
std::vector<Texel> surroundedPixel(double nearer_mm) {
  std::vector<Texel> texels = {{16, 16, {1, 0, 0}, 100.0, 1}};
  for (uint32_t y = 4; y < 29; ++y)
    for (uint32_t x = 4; x < 29; ++x)
      if ((x != 16 || y != 16) && (int(x) - 16) * (int(x) - 16) + (int(y) - 16) * (int(y) - 16) <= 144)
        texels.push_back({x, y, {0, 1, 0}, 100.0 - nearer_mm, 2});
  return texels;
}

TEST_F(GpuShade, ssaoDarkensAPixelSurroundedByNearerFibers) {
  RenderSettings s;
  s.ssao_strength = 0.8f;
  s.ssao_radius_px = 8.0f;
  s.ssao_range_mm = 6.0f;
  const std::vector<Texel> texels = surroundedPixel(2.0);
  s.ssao = false;
  const auto plain = pixel(shade(texels, s), 16, 16);
  s.ssao = true;
  const std::vector<uint8_t> with_ao = shade(texels, s);
  const auto dark = pixel(with_ao, 16, 16);
  std::printf("centre luminance %.1f without SSAO, %.1f with\n", luminance(plain), luminance(dark));
  EXPECT_LT(luminance(dark), 0.6 * luminance(plain));
  // The nearer disc has nothing in front of it.
  s.ssao = false;
  const std::vector<uint8_t> plain_all = shade(texels, s);
  EXPECT_EQ(pixel(with_ao, 10, 16), pixel(plain_all, 10, 16));
}

TEST_F(GpuShade, ssaoIgnoresForegroundBeyondTheRange) {
  RenderSettings s;
  s.ssao_strength = 1.0f;
  s.ssao_range_mm = 6.0f;
  const std::vector<Texel> texels = surroundedPixel(30.0);
  s.ssao = false;
  const auto plain = pixel(shade(texels, s), 16, 16);
  s.ssao = true;
  EXPECT_EQ(pixel(shade(texels, s), 16, 16), plain);
  // Side by side in depth (within the epsilon) does not occlude either.
  const std::vector<Texel> side_by_side = surroundedPixel(0.1);
  s.ssao = false;
  const auto plain_side = pixel(shade(side_by_side, s), 16, 16);
  s.ssao = true;
  EXPECT_EQ(pixel(shade(side_by_side, s), 16, 16), plain_side);
}

TEST_F(GpuShade, settingsOutOfRangeAreRejected) {
  RenderSettings s;
  s.ssao_strength = 1.5f;
  EXPECT_THROW(shade({}, s), Error);
  s = {};
  s.ssao_radius_px = std::nanf("");
  EXPECT_THROW(shade({}, s), Error);
  s = {};
  s.ssao_range_mm = 0.0f;
  EXPECT_THROW(shade({}, s), Error);
  s = {};
  s.light_shininess = 0.0f;
  EXPECT_THROW(shade({}, s), Error);
}

Tractogram phantom(uint64_t streamlines, uint64_t seed) {
  PhantomOptions options;
  options.streamlines = streamlines;
  options.step_mm = 0.5;
  options.seed = seed;
  options.threads = 1;
  return readAllStreamlines(*openPhantom(options));
}

TEST_F(GpuShade, wholePhantomFramesInEveryModeAreShaded) {
  const Tractogram fibers = phantom(300, 3);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  const Bounds bounds = tractogramBounds(fibers);
  constexpr uint32_t kFrame = 256;
  FrameRenderer renderer(context(), kFrame, kFrame);
  const Camera camera = standardView(bounds, StandardView::Sagittal, kFrame, kFrame);
  RenderSettings s;
  s.culling = CullingMode::None;
  for (ColorMode mode : {ColorMode::Solid, ColorMode::Orientation, ColorMode::PerFiber})
    for (Lighting lighting : {Lighting::None, Lighting::IlluminatedLines})
      for (bool ssao : {false, true}) {
        SCOPED_TRACE(std::string(colorModeName(mode)) + " " + std::string(lightingName(lighting)) +
                     (ssao ? " ssao" : ""));
        s.color = mode;
        s.lighting = lighting;
        s.ssao = ssao;
        const FrameStats stats = renderer.render(camera, s, GpuScene{&upload.dataset});
        bool timed_shade = false;
        for (const PassTiming& p : stats.passes) timed_shade |= p.name == "shade";
        EXPECT_TRUE(timed_shade);
        const std::vector<uint8_t> rgba = downloadColor(context(), renderer.targets());
        const auto texels = downloadGBuffer(context(), renderer.targets());
        std::set<uint32_t> colors;
        size_t covered = 0, background_ok = 0;
        for (size_t i = 0; i < texels.size(); ++i) {
          const uint32_t c = uint32_t(rgba[4 * i]) | uint32_t(rgba[4 * i + 1]) << 8 | uint32_t(rgba[4 * i + 2]) << 16 |
                             uint32_t(rgba[4 * i + 3]) << 24;
          if (texels[i].fiber == shader::kNoFiberId) {
            background_ok += c == 0xFF000000u;
          } else {
            ++covered;
            colors.insert(c);
          }
        }
        EXPECT_EQ(background_ok, texels.size() - covered);
        EXPECT_GT(covered, kFrame * kFrame / 20);
        // Solid without lighting or SSAO is one colour; everything else varies.
        if (mode == ColorMode::Solid && lighting == Lighting::None && !ssao)
          EXPECT_EQ(colors.size(), 1u);
        else
          EXPECT_GT(colors.size(), 30u);
      }
  // A resized renderer shades at its new size.
  renderer.resize(128, 96);
  const Camera small = standardView(bounds, StandardView::Axial, 128, 96);
  renderer.render(small, RenderSettings{}, GpuScene{&upload.dataset});
  const std::vector<uint8_t> rgba = downloadColor(context(), renderer.targets());
  ASSERT_EQ(rgba.size(), 128u * 96u * 4u);
  EXPECT_GT(std::count_if(rgba.begin(), rgba.end(), [](uint8_t v) { return v != 0 && v != 255; }), 1000);
}

}  // namespace
}  // namespace fibscope
