// The shading stages (src/render/gpu/shading_stages.h) on hand-made G-buffers,
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
#include <limits>
#include <set>
#include <vector>

#include "core/error.h"
#include "gpu/submit.h"
#include "gpu_given_gbuffer_stage.h"
#include "gpu_test_context.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/camera.h"
#include "render/colormap.h"
#include "render/gpu/fiber_attributes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/shading_stages.h"
#include "render/gpu/tractogram_upload.h"
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
// The unit vector from the texel's surface point to the eye: the world
// position of the pixel centre at its depth, through the inverse
// view-projection.
V3 towardsEye(const Camera& camera, const Texel& t) {
  const auto inv = inverse(viewProjectionD(camera));
  const double ndc[4] = {(t.x + 0.5) / camera.width * 2 - 1, (t.y + 0.5) / camera.height * 2 - 1,
                         double(clipDepth(camera, t.distance_mm)), 1};
  double w[4] = {0, 0, 0, 0};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) w[r] += inv[4 * c + r] * ndc[c];
  const V3 world = {w[0] / w[3], w[1] / w[3], w[2] / w[3]};
  return normalized(sub(camera.eye, world));
}

// The camera's look-at frame: right, up, back (towards the eye).
std::array<V3, 3> viewAxes(const Camera& camera) {
  const V3 back = normalized(sub(camera.eye, camera.target));
  const V3 right = normalized(cross(camera.up, back));
  return {right, cross(back, right), back};
}

// A view-space vector (x right, y up, z towards the eye) in world space.
V3 viewToWorld(const Camera& camera, V3 w) {
  const auto axes = viewAxes(camera);
  V3 out{};
  for (int j = 0; j < 3; ++j) out[j] = w[0] * axes[0][j] + w[1] * axes[1][j] + w[2] * axes[2][j];
  return out;
}

// The headlight (kShadeLightView*) in world space.
V3 headlight(const Camera& camera) {
  return viewToWorld(camera,
                     normalized({shader::kShadeLightViewX, shader::kShadeLightViewY, shader::kShadeLightViewZ}));
}

// ColorMode::Normal's promise: N = normalize(V - (V.T) T), or V for a line
// seen end-on, in view space, as 0.5 + 0.5 N.
Rgb expectedNormalColor(const Camera& camera, const Texel& t) {
  const V3 tangent = normalized(t.tangent), v = towardsEye(camera, t);
  const double vt = dot(v, tangent);
  V3 n = {v[0] - vt * tangent[0], v[1] - vt * tangent[1], v[2] - vt * tangent[2]};
  n = std::sqrt(dot(n, n)) > 1e-3 ? normalized(n) : v;
  const auto axes = viewAxes(camera);
  return {0.5 + 0.5 * dot(n, axes[0]), 0.5 + 0.5 * dot(n, axes[1]), 0.5 + 0.5 * dot(n, axes[2])};
}

// The colour the shading promises for one texel, computed on the CPU;
// `base`, when given, replaces the colour mode's (scalar and highlight
// colours come from tables the tests check separately).
Rgb expectedColor(const Camera& camera, const RenderSettings& s, const Texel& t, const Rgb* base_override = nullptr) {
  const V3 tangent = normalized(t.tangent);
  Rgb base{};
  switch (s.color) {
    case ColorMode::Solid: base = {s.solid_color[0], s.solid_color[1], s.solid_color[2]}; break;
    case ColorMode::Orientation:
      base = {std::fabs(tangent[0]), std::fabs(tangent[1]), std::fabs(tangent[2])};
      break;
    case ColorMode::PerFiber: base = expectedFiberColor(t.fiber); break;
    case ColorMode::Normal: base = expectedNormalColor(camera, t); break;
    case ColorMode::Scalar:
      if (!base_override) ADD_FAILURE() << "scalar colours need the table entry";
      break;
  }
  if (base_override) base = *base_override;
  if (s.lighting == Lighting::None) return base;
  const V3 v = towardsEye(camera, t);
  const V3 l = headlight(camera);
  const double lt = dot(l, tangent), vt = dot(v, tangent);
  const double diffuse = std::sqrt(std::max(0.0, 1 - lt * lt));
  const double specular =
      std::pow(std::max(0.0, diffuse * std::sqrt(std::max(0.0, 1 - vt * vt)) - lt * vt), s.light_shininess);
  Rgb c{};
  for (int k = 0; k < 3; ++k) c[k] = base[k] * (s.light_ambient + s.light_diffuse * diffuse) + s.light_specular * specular;
  return c;
}

// What the shaded fibers' attributes are (GpuScene's) and how many fibers
// they cover.
struct ShadeFiberInputs {
  VkDeviceAddress fiber_scalars = 0;
  VkDeviceAddress selection_bits = 0;
  uint32_t fiber_count = 0;
};

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
  std::vector<uint8_t> shade(const std::vector<Texel>& texels, const RenderSettings& settings,
                             const ShadeFiberInputs& fibers = {}) {
    std::vector<shader::GBufferTexel> gbuffer(kSize * kSize, {1.0f, shader::kNoFiberId, 0, 0});
    for (const Texel& t : texels)
      gbuffer[t.y * kSize + t.x] = {clipDepth(camera(), t.distance_mm), t.fiber, 0, packTangent(t.tangent)};
    return shadeGBuffer(camera(), gbuffer, settings, fibers);
  }

  // Shades `gbuffer` (camera.width x camera.height texels) through the
  // shading stages of a FrameRenderer and returns RGBA8; with `tile_list`,
  // also the tiles stage's list as the words of its buffer (header, then
  // one index per tile at most).
  std::vector<uint8_t> shadeGBuffer(const Camera& cam, const std::vector<shader::GBufferTexel>& gbuffer,
                                    const RenderSettings& settings, const ShadeFiberInputs& fibers = {},
                                    std::vector<uint32_t>* tile_list = nullptr) {
    FrameRenderer renderer(context(), cam.width, cam.height, test::givenGBufferStages(gbuffer, fibers.fiber_count));
    GpuScene scene;
    scene.fiber_scalars = fibers.fiber_scalars;
    scene.selection_bits = fibers.selection_bits;
    renderer.render(cam, settings, scene);
    if (tile_list) {
      const gpu::Buffer& list = renderer.targets().tile_list;
      tile_list->resize(list.size / sizeof(uint32_t));
      gpu::downloadFromBuffer(context(), list, tile_list->data(), list.size);
    }
    return downloadColor(context(), renderer.targets());
  }

  static std::array<uint8_t, 4> pixel(const std::vector<uint8_t>& rgba, uint32_t x, uint32_t y) {
    const size_t i = 4 * (size_t(y) * kSize + x);
    return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
  }
  static double luminance(std::array<uint8_t, 4> p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

  // Colour channels within `tolerance`, alpha exact.
  static void expectNear(std::array<uint8_t, 4> got, std::array<uint8_t, 4> want, const char* what,
                         int tolerance = 2) {
    for (int k = 0; k < 4; ++k)
      EXPECT_LE(std::abs(int(got[k]) - int(want[k])), k == 3 ? 0 : tolerance)
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
  const V3 back = viewAxes(c)[2];
  const V3 l = headlight(c);
  const V3 across = normalized(cross(l, back));  // ~perpendicular to L and V at the centre
  const std::vector<Texel> texels = {{16, 16, across, 100, 1}, {20, 16, back, 100, 2}};
  const std::vector<uint8_t> rgba = shade(texels, s);
  const auto lit = pixel(rgba, 16, 16), dim = pixel(rgba, 20, 16);
  EXPECT_GT(lit[0], 0.5 * (s.light_ambient + s.light_diffuse) * 255 + 0.8 * s.light_specular * 255);
  EXPECT_LT(dim[0], lit[0] / 2);
  expectNear(lit, quantize(expectedColor(c, s, texels[0])), "highlight");
}

// PBR's promise (shared/shade_push.h), in double precision and written
// from the formulas: Cook-Torrance with GGX, Schlick-GGX/Smith and
// Fresnel-Schlick under 30 directional lights on a ring at 45 degrees
// around the direction towards the eye (camera frame), plus ambient.
Rgb expectedPbr(const Camera& camera, const RenderSettings& s, V3 n, V3 v, Rgb albedo) {
  const double pi = 3.14159265358979323846;
  const double rough = s.pbr_roughness, metal = s.pbr_metalness;
  const double a2 = std::pow(rough, 4.0), k = (rough + 1) * (rough + 1) / 8;
  auto g1 = [k](double x) { return x / (x * (1 - k) + k); };
  const double nv = std::max(0.0, dot(n, v));
  Rgb c{};
  for (int ch = 0; ch < 3; ++ch) c[ch] = s.light_ambient * albedo[ch];
  for (int i = 0; i < 30; ++i) {
    const double azimuth = 2 * pi * i / 30, polar = pi / 4;
    const V3 l = viewToWorld(camera, {std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
                                      std::cos(polar)});
    const double nl = dot(n, l);
    if (nl <= 0) continue;
    const V3 h = normalized({l[0] + v[0], l[1] + v[1], l[2] + v[2]});
    const double nh = std::max(0.0, dot(n, h)), hv = std::max(0.0, dot(h, v));
    const double d = a2 / (pi * std::pow(nh * nh * (a2 - 1) + 1, 2));
    const double g = g1(nv) * g1(nl);
    for (int ch = 0; ch < 3; ++ch) {
      const double f0 = 0.04 * (1 - metal) + albedo[ch] * metal;
      const double f = f0 + (1 - f0) * std::pow(1 - hv, 5);
      const double diffuse = (1 - f) * (1 - metal) * albedo[ch] / pi;
      const double specular = d * g * f / std::max(4 * nl * nv, 1e-4);
      c[ch] += (diffuse + specular) * s.pbr_intensity / 30 * nl;
    }
  }
  return c;
}

// The line's view-facing normal (in the plane of T and V), as PBR lights it.
V3 viewFacingNormal(V3 t, V3 v) {
  t = normalized(t);
  const double vt = dot(v, t);
  const V3 n = {v[0] - vt * t[0], v[1] - vt * t[1], v[2] - vt * t[2]};
  return std::sqrt(dot(n, n)) > 1e-3 ? normalized(n) : v;
}

TEST_F(GpuShade, pbrLinesMatchTheCpuCookTorrance) {
  RenderSettings s;
  s.lighting = Lighting::Pbr;
  s.ssao = false;
  const std::vector<Texel> texels = sampleTexels();
  const Camera c = camera();
  struct Material {
    float roughness, metalness, intensity;
  };
  // Rough dielectric, the defaults, glossy metal (large, narrow highlights),
  // and a half-metal under a dimmer ring.
  for (Material m : {Material{1.0f, 0.0f, 3.14159265f}, Material{0.5f, 0.0f, 3.14159265f},
                     Material{0.15f, 1.0f, 3.14159265f}, Material{0.3f, 0.5f, 2.0f}})
    for (ColorMode mode : {ColorMode::Solid, ColorMode::Orientation}) {
      SCOPED_TRACE("roughness " + std::to_string(m.roughness) + " metalness " + std::to_string(m.metalness) + " " +
                   std::string(colorModeName(mode)));
      s.pbr_roughness = m.roughness;
      s.pbr_metalness = m.metalness;
      s.pbr_intensity = m.intensity;
      s.color = mode;
      s.solid_color = {0.8f, 0.5f, 0.2f};
      const std::vector<uint8_t> rgba = shade(texels, s);
      for (const Texel& t : texels) {
        const V3 tangent = normalized(t.tangent), v = towardsEye(c, t);
        const Rgb albedo = mode == ColorMode::Solid ? Rgb{s.solid_color[0], s.solid_color[1], s.solid_color[2]}
                                                    : Rgb{std::fabs(tangent[0]), std::fabs(tangent[1]),
                                                          std::fabs(tangent[2])};
        expectNear(pixel(rgba, t.x, t.y), quantize(expectedPbr(c, s, viewFacingNormal(tangent, v), v, albedo)),
                   "pbr line texel", 1);
      }
    }
}

TEST_F(GpuShade, pbrSurfacesAreLitFromTheirNormal) {
  // Surface texels (a tube's) with normals facing the eye, across it and
  // away from it (the shade pass turns those towards the eye), through the
  // merge, against the same formulas with the surface's own normal.
  RenderSettings s;
  s.lighting = Lighting::Pbr;
  s.ssao = false;
  s.color = ColorMode::Solid;
  s.solid_color = {0.3f, 0.6f, 0.9f};
  s.pbr_roughness = 0.35f;
  s.pbr_metalness = 0.2f;
  const Camera c = camera();
  std::vector<shader::GBufferTexel> gbuffer(kSize * kSize, {1.0f, shader::kNoFiberId, 0, 0});
  std::vector<shader::SurfaceTexel> surfaces(kSize * kSize, shader::SurfaceTexel{1.0f, shader::kNoFiberId});
  struct Case {
    uint32_t x, y;
    V3 normal;
  };
  std::vector<Case> cases;
  const double w[][3] = {{0, 0, 1}, {0.6, 0.3, 0.74}, {-0.9, 0.1, 0.42}, {0.2, -0.95, 0.24}, {0.3, 0.2, -0.93}};
  uint32_t i = 0;
  for (const auto& m : w) {
    cases.push_back({4 + 5 * i, 6 + 4 * i, normalized(viewToWorld(c, {m[0], m[1], m[2]}))});
    ++i;
  }
  for (const Case& k : cases) {
    shader::SurfaceTexel& t = surfaces[k.y * kSize + k.x];
    t.depth = clipDepth(c, 100.0);
    t.fiber = 3;
    t.normal = packTangent(k.normal);
    t.tangent = packTangent({1, 0, 0});
    t.source = shader::kSurfaceSourceTube;
  }
  FrameRenderer renderer(context(), c.width, c.height, test::givenGBufferStages(gbuffer, 0, surfaces));
  renderer.render(c, s, GpuScene{});
  const std::vector<uint8_t> rgba = downloadColor(context(), renderer.targets());
  for (const Case& k : cases) {
    const V3 v = towardsEye(c, {k.x, k.y, {1, 0, 0}, 100.0, 3});
    V3 n = k.normal;
    if (dot(n, v) < 0) n = {-n[0], -n[1], -n[2]};
    expectNear(pixel(rgba, k.x, k.y),
               quantize(expectedPbr(c, s, n, v, {s.solid_color[0], s.solid_color[1], s.solid_color[2]})),
               "pbr surface texel", 1);
  }
  // A normal facing the eye is lit by the whole ring; one at 65 degrees
  // from it by fewer lights, so it is darker.
  EXPECT_GT(luminance(pixel(rgba, cases[0].x, cases[0].y)), luminance(pixel(rgba, cases[2].x, cases[2].y)));
}

TEST_F(GpuShade, pbrParametersOutOfRangeAreRejected) {
  RenderSettings s;
  s.lighting = Lighting::Pbr;
  s.pbr_roughness = 0.0f;
  EXPECT_THROW(shade({}, s), Error);
  s.pbr_roughness = 0.5f;
  s.pbr_metalness = 1.5f;
  EXPECT_THROW(shade({}, s), Error);
  s.pbr_metalness = 0.5f;
  s.pbr_intensity = -1.0f;
  EXPECT_THROW(shade({}, s), Error);
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

TEST_F(GpuShade, ssaoRotationPatternIsAveragedAwayWhereTheDepthIsEven) {
  // A bundle at 100 mm whose left part (x < 14) is covered by a nearer one
  // at 98 mm: the pixels of the far bundle near the edge see the near one
  // with a share of their samples that depends on the spiral's turn, which
  // changes from pixel to pixel in the 4 x 4 tile. Along a column the scene
  // is the same, so after the blur every interior row must be the same
  // colour (a hash per pixel, or blur weights that favour some phases,
  // leave a pattern).
  RenderSettings s;
  s.ssao_strength = 1.0f;
  s.ssao_radius_px = 5.0f;
  s.ssao_range_mm = 6.0f;
  // White, unlit: the pixel is 255 times the occlusion factor.
  s.color = ColorMode::Solid;
  s.solid_color = {1.0f, 1.0f, 1.0f};
  s.lighting = Lighting::None;
  std::vector<Texel> texels;
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      texels.push_back({x, y, {0, 1, 0}, x < 14 ? 98.0 : 100.0, x < 14 ? 3u : 2u});
  s.ssao = false;
  const std::vector<uint8_t> plain = shade(texels, s);
  s.ssao = true;
  const std::vector<uint8_t> with_ao = shade(texels, s);
  // Rows at least radius + blur radius from the top and bottom edges.
  for (uint32_t x = 14; x < 20; ++x) {
    const auto first = pixel(with_ao, x, 8);
    for (uint32_t y = 9; y < 24; ++y)
      for (int k = 0; k < 3; ++k)
        ASSERT_LE(std::abs(int(pixel(with_ao, x, y)[k]) - int(first[k])), 1)
            << "column " << x << " row " << y << " channel " << k;
  }
  // The edge of the far bundle is occluded, its far side not.
  EXPECT_LT(luminance(pixel(with_ao, 14, 16)), 0.85 * luminance(pixel(plain, 14, 16)));
  EXPECT_EQ(pixel(with_ao, 28, 16), pixel(plain, 28, 16));
}

TEST_F(GpuShade, tileListHoldsExactlyTheTilesWithACoveredPixel) {
  // A frame of partial tiles (45 x 27: 6 x 4 tiles, the last column 5 px
  // wide, the last row 3 px high), covered pixels in the corner tiles, in
  // the partial ones and scattered; the listed tiles must be exactly the
  // brute-force set, each once, and every pixel outside them the
  // background (shade writes the listed tiles only).
  constexpr uint32_t kW = 45, kH = 27, kTilesX = 6, kTilesY = 4;
  Camera cam = camera();
  cam.width = kW;
  cam.height = kH;
  std::vector<shader::GBufferTexel> gbuffer(kW * kH, {1.0f, shader::kNoFiberId, 0, 0});
  const uint32_t covered[][2] = {{0, 0}, {44, 26}, {40, 3}, {7, 7}, {8, 8}, {9, 8}, {20, 26}, {44, 0}, {31, 13}};
  std::set<uint32_t> expected;
  for (const auto& c : covered) {
    gbuffer[c[1] * kW + c[0]] = {clipDepth(cam, 100.0), 3, 0, packTangent({0, 1, 0})};
    expected.insert(c[1] / 8 * kTilesX + c[0] / 8);
  }
  RenderSettings s;
  s.background = {0.2f, 0.4f, 0.6f};
  std::vector<uint32_t> list;
  const std::vector<uint8_t> rgba = shadeGBuffer(cam, gbuffer, s, {}, &list);
  ASSERT_EQ(list.size(), 4 + kTilesX * kTilesY) << "header + a word per tile";
  const uint32_t count = list[3];  // FibletListHeader: dispatch x, y, z, count
  ASSERT_EQ(count, expected.size());
  EXPECT_EQ(list[0] * list[1] * list[2], count) << "the indirect dispatch is one workgroup per tile";
  const std::multiset<uint32_t> listed(list.begin() + 4, list.begin() + 4 + count);
  EXPECT_EQ(std::set<uint32_t>(listed.begin(), listed.end()), expected);
  EXPECT_EQ(listed.size(), std::set<uint32_t>(listed.begin(), listed.end()).size()) << "a tile listed twice";
  const uint8_t bg[3] = {uint8_t(0.2f * 255 + 0.5f), uint8_t(0.4f * 255 + 0.5f), uint8_t(0.6f * 255 + 0.5f)};
  size_t drawn = 0;
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      const uint8_t* p = &rgba[4 * (y * kW + x)];
      const bool is_background = p[0] == bg[0] && p[1] == bg[1] && p[2] == bg[2] && p[3] == 255;
      const bool fiber = gbuffer[y * kW + x].fiber != shader::kNoFiberId;
      EXPECT_EQ(is_background, !fiber) << "pixel " << x << ", " << y;
      drawn += fiber;
    }
  EXPECT_EQ(drawn, std::size(covered));
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
    for (Lighting lighting : {Lighting::None, Lighting::IlluminatedLines, Lighting::Pbr})
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


// --- Colour modes of the viewer: scalar through a colormap, normal, selection.

Rgb unpackEntry(uint32_t c) { return {(c & 255u) / 255.0, ((c >> 8) & 255u) / 255.0, ((c >> 16) & 255u) / 255.0}; }

TEST_F(GpuShade, scalarColorsAreTheColormapEntryClampedToTheRange) {
  // Fibers 0..7 with scalars below, at, inside and above [10, 30] mm.
  const std::vector<float> scalars = {-5.0f, 10.0f, 15.0f, 20.0f, 25.0f, 30.0f, 400.0f, std::nanf("")};
  GpuFiberAttributes attributes(context(), scalars.size());
  attributes.uploadScalars(scalars);
  std::vector<Texel> texels;
  for (uint32_t f = 0; f < scalars.size(); ++f) texels.push_back({3 + 3 * f, 5 + 2 * f, {1, 0.2, 0.3}, 90.0, f});
  RenderSettings s;
  s.color = ColorMode::Scalar;
  s.lighting = Lighting::None;
  s.ssao = false;
  s.scalar_min = 10.0f;
  s.scalar_max = 30.0f;
  for (Colormap map : {Colormap::Viridis, Colormap::Magma, Colormap::Grayscale, Colormap::CoolWarm}) {
    SCOPED_TRACE(std::string(colormapName(map)));
    s.colormap = map;
    const std::vector<uint32_t> table = colormapTable(map);
    const std::vector<uint8_t> rgba =
        shade(texels, s, ShadeFiberInputs{attributes.scalars(), 0, uint32_t(scalars.size())});
    // Entry round(255 t), t clamped; NaN takes the low end.
    const uint32_t entries[] = {0, 0, 64, 128, 191, 255, 255, 0};
    for (const Texel& t : texels) {
      const uint32_t want = table[entries[t.fiber]];
      const auto p = pixel(rgba, t.x, t.y);
      EXPECT_EQ(uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24, want)
          << "fiber " << t.fiber << " scalar " << scalars[t.fiber];
    }
    // The ends of the range are the colormap's first and last control points.
    const auto points = colormapControlPoints(map);
    expectNear(pixel(rgba, texels[1].x, texels[1].y), quantize({points.front()[0], points.front()[1], points.front()[2]}),
               "low end");
    expectNear(pixel(rgba, texels[5].x, texels[5].y), quantize({points.back()[0], points.back()[1], points.back()[2]}),
               "high end");
  }
  // Lit: the entry is the base colour of the illuminated-lines formula.
  s.lighting = Lighting::IlluminatedLines;
  s.colormap = Colormap::Viridis;
  const std::vector<uint32_t> table = colormapTable(Colormap::Viridis);
  const std::vector<uint8_t> lit = shade(texels, s, ShadeFiberInputs{attributes.scalars(), 0, uint32_t(scalars.size())});
  const Rgb mid = unpackEntry(table[128]);
  expectNear(pixel(lit, texels[3].x, texels[3].y), quantize(expectedColor(camera(), s, texels[3], &mid)), "lit mid");
}

TEST_F(GpuShade, scalarModeWithoutScalarsFallsBackToOrientation) {
  RenderSettings s;
  s.lighting = Lighting::None;
  s.ssao = false;
  const std::vector<Texel> texels = sampleTexels();
  s.color = ColorMode::Orientation;
  const std::vector<uint8_t> orientation = shade(texels, s);
  s.color = ColorMode::Scalar;
  EXPECT_EQ(shade(texels, s), orientation);
  // Fiber ids past the scalars' count fall back too (never read past the end).
  GpuFiberAttributes attributes(context(), 4);
  attributes.uploadScalars(std::vector<float>{1, 2, 3, 4});
  EXPECT_EQ(shade(texels, s, ShadeFiberInputs{attributes.scalars(), 0, 4}), orientation);
}

TEST_F(GpuShade, normalColorsAreTheViewFacingNormalInViewSpace) {
  RenderSettings s;
  s.color = ColorMode::Normal;
  s.lighting = Lighting::None;
  s.ssao = false;
  std::vector<Texel> texels = sampleTexels();
  // A line seen end-on: its tangent is the direction to the eye at its pixel.
  Texel end_on{16, 16, {0, 0, 1}, 100.0, 9};
  end_on.tangent = towardsEye(camera(), end_on);
  texels.push_back(end_on);
  const std::vector<uint8_t> rgba = shade(texels, s);
  for (const Texel& t : texels) expectNear(pixel(rgba, t.x, t.y), quantize(expectedNormalColor(camera(), t)), "normal");
  // End-on, N = V: nearly the view axis, so blue near 1 and red, green near 0.5.
  const auto p = pixel(rgba, 16, 16);
  EXPECT_GE(p[2], 250);
  EXPECT_NEAR(p[0], 128, 20);
  EXPECT_NEAR(p[1], 128, 20);
  // Every normal faces the viewer (z >= 0 in view space: blue >= 0.5).
  for (const Texel& t : texels) EXPECT_GE(pixel(rgba, t.x, t.y)[2], 127) << "texel " << t.x << ", " << t.y;
  // Lit, the normal colour is the base of the illuminated-lines formula.
  s.lighting = Lighting::IlluminatedLines;
  const std::vector<uint8_t> lit = shade(texels, s);
  for (const Texel& t : texels) expectNear(pixel(lit, t.x, t.y), quantize(expectedColor(camera(), s, t)), "lit normal");
}

TEST_F(GpuShade, selectedFibersAreHighlightedAndTheOthersDimmed) {
  RenderSettings s;
  s.color = ColorMode::Orientation;
  s.ssao = false;
  s.background = {0.1f, 0.1f, 0.2f};
  s.highlight_color = {1.0f, 0.5f, 0.0f};
  s.dim_unselected = 0.75f;
  const std::vector<Texel> texels = sampleTexels();  // fibers 100 + 37 i
  constexpr uint32_t kFibers = 600;
  std::vector<uint32_t> words(selectionWordCount(kFibers), 0);
  std::set<uint32_t> selected = {texels[0].fiber, texels[3].fiber, texels[7].fiber};
  for (uint32_t f : selected) words[f / 32] |= 1u << (f % 32);
  GpuFiberAttributes attributes(context(), kFibers);
  EXPECT_EQ(attributes.selection(), 0u) << "nothing uploaded: no selection";
  attributes.uploadSelection(words);
  EXPECT_EQ(attributes.selectedCount(), 3u);
  const Rgb bg = {s.background[0], s.background[1], s.background[2]};
  const Rgb highlight = {s.highlight_color[0], s.highlight_color[1], s.highlight_color[2]};
  for (Lighting lighting : {Lighting::None, Lighting::IlluminatedLines}) {
    SCOPED_TRACE(std::string(lightingName(lighting)));
    s.lighting = lighting;
    const std::vector<uint8_t> rgba = shade(texels, s, ShadeFiberInputs{0, attributes.selection(), kFibers});
    for (const Texel& t : texels) {
      if (selected.count(t.fiber)) {
        expectNear(pixel(rgba, t.x, t.y), quantize(expectedColor(camera(), s, t, &highlight)), "selected");
      } else {
        const Rgb plain = expectedColor(camera(), s, t);
        Rgb dimmed{};
        // Mixed before the final clamp to [0, 1], as the shader does.
        for (int k = 0; k < 3; ++k) dimmed[k] = plain[k] + s.dim_unselected * (bg[k] - plain[k]);
        expectNear(pixel(rgba, t.x, t.y), quantize(dimmed), "unselected");
      }
    }
  }
  // An empty selection (address 0) dims nothing.
  attributes.uploadSelection(std::vector<uint32_t>(selectionWordCount(kFibers), 0));
  EXPECT_EQ(attributes.selection(), 0u);
  EXPECT_EQ(shade(texels, s, ShadeFiberInputs{0, attributes.selection(), kFibers}), shade(texels, s));
  // Words of the wrong count, or bits past the last fiber, are refused.
  EXPECT_THROW(attributes.uploadSelection(std::vector<uint32_t>(3, 0)), Error);
  std::vector<uint32_t> past(selectionWordCount(kFibers), 0);
  past.back() = 1u << 31;  // fiber 607
  EXPECT_THROW(attributes.uploadSelection(past), Error);
  EXPECT_THROW(attributes.uploadScalars(std::vector<float>(kFibers - 1, 0.0f)), Error);
}

// Fiber 1 at the centre (100 mm), a ring of fiber 2 at 14 to 18 px around
// it, 2 mm nearer: beyond the first scale's radius, within the third's.
std::vector<Texel> ringAroundPixel() {
  std::vector<Texel> texels = {{16, 16, {1, 0, 0}, 100.0, 1}};
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 32; ++x) {
      const int d2 = (int(x) - 16) * (int(x) - 16) + (int(y) - 16) * (int(y) - 16);
      if (d2 >= 14 * 14 && d2 <= 18 * 18) texels.push_back({x, y, {0, 1, 0}, 98.0, 2});
    }
  return texels;
}

TEST_F(GpuShade, multiScaleAoReachesFartherAndNeverLightens) {
  RenderSettings s;
  s.ssao_radius_px = 5.0f;
  s.ssao_strength = 0.8f;
  s.ssao_range_mm = 6.0f;
  const std::vector<Texel> ring = ringAroundPixel();
  s.ssao = false;
  const auto plain = pixel(shade(ring, s), 16, 16);
  s.ssao = true;
  s.ao_scales = 1;
  const auto one = pixel(shade(ring, s), 16, 16);
  EXPECT_EQ(one, plain) << "the ring lies beyond a single scale's 5 px";
  s.ao_scales = 3;  // 5, 10, 20 px
  const auto three = pixel(shade(ring, s), 16, 16);
  std::printf("centre luminance %.1f with 1 scale, %.1f with 3\n", luminance(one), luminance(three));
  EXPECT_LT(luminance(three), 0.9 * luminance(one));
  // Per pixel, each added scale darkens or keeps every pixel (the factors
  // multiply and the blur is linear with the same weights).
  std::vector<Texel> scene = surroundedPixel(2.0);
  for (const Texel& t : ring)
    if (t.fiber == 2 && (t.x < 4 || t.x >= 29 || t.y < 4 || t.y >= 29)) scene.push_back({t.x, t.y, t.tangent, 97.0, 3});
  std::vector<uint8_t> previous;
  for (int scales = 1; scales <= 5; ++scales) {
    s.ao_scales = scales;
    const std::vector<uint8_t> rgba = shade(scene, s);
    if (!previous.empty()) {
      for (size_t i = 0; i < rgba.size(); ++i) ASSERT_LE(rgba[i], previous[i]) << scales << " scales, byte " << i;
    }
    previous = rgba;
  }
  s.ao_scales = 0;
  EXPECT_THROW(shade({}, s), Error);
  s.ao_scales = 6;
  EXPECT_THROW(shade({}, s), Error);
  s.ao_scales = 1;
  s.ao_samples = 2;
  EXPECT_THROW(shade({}, s), Error);
  s.ao_samples = 65;
  EXPECT_THROW(shade({}, s), Error);
}

// The ambient-occlusion factor the SSAO and its blur promise
// (shared/shade_push.h: SsaoPush, SsaoBlurPush), on the CPU in double
// precision: per covered pixel the Vogel spiral of each scale (radius r 2^k,
// max(samples >> k, 4) neighbours, turned by the pixel's 4 x 4 Bayer phase
// and k golden angles), the per-scale factors multiplied, then the 1 2 2 2 1
// blur along x and then y over covered pixels within the depth tolerance.
std::vector<double> referenceAo(const Camera& cam, const std::vector<shader::GBufferTexel>& g,
                                const RenderSettings& s) {
  const int w = int(cam.width), h = int(cam.height);
  const double golden = 2.39996323, pi = 3.14159265358979323846;
  auto distance = [&](float d) { return cam.near_mm * cam.far_mm / (cam.far_mm - d * (cam.far_mm - cam.near_mm)); };
  auto covered = [&](int i) { return g[i].fiber != shader::kNoFiberId; };
  auto smoothstep = [](double a, double b, double x) {
    const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
    return t * t * (3 - 2 * t);
  };
  std::vector<double> ao(g.size(), 1.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (!covered(i) || g[i].fiber == shader::kNoFiberObject) continue;
      const double z = distance(g[i].depth);
      const int bayer = ((x ^ y) & 1) << 3 | (y & 1) << 2 | ((x ^ y) & 2) | (y & 2) >> 1;
      const double rotation = (bayer + 0.5) * 2 * pi / 16;
      for (int k = 0; k < s.ao_scales; ++k) {
        const double radius = s.ssao_radius_px * (1 << k);
        const int samples = std::max(s.ao_samples >> k, 4);
        double occluded = 0, total = 0;
        for (int j = 0; j < samples; ++j) {
          const double r = radius * std::sqrt((j + 0.5) / samples), a = j * golden + rotation + k * golden;
          const double weight = 1 - 0.5 * r / radius;
          total += weight;
          const int qx = int(std::floor(x + 0.5 + r * std::cos(a))), qy = int(std::floor(y + 0.5 + r * std::sin(a)));
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const shader::GBufferTexel& t = g[qy * w + qx];
          if (t.fiber == shader::kNoFiberId || t.fiber == shader::kNoFiberObject || t.fiber == g[i].fiber) continue;
          const double nearer = z - distance(t.depth);
          if (nearer > shader::kSsaoEpsilonMm && nearer < s.ssao_range_mm)
            occluded += weight * (1 - smoothstep(0.5 * s.ssao_range_mm, s.ssao_range_mm, nearer));
        }
        ao[i] *= 1 - s.ssao_strength * occluded / total;
      }
    }
  for (const auto [sx, sy] : {std::pair{1, 0}, std::pair{0, 1}}) {
    std::vector<double> out = ao;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int i = y * w + x;
        if (!covered(i)) continue;
        double sum = 2 * ao[i], total = 2;
        for (int k = -2; k <= 2; ++k) {
          const int qx = x + k * sx, qy = y + k * sy;
          if (k == 0 || qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
          const int q = qy * w + qx;
          if (!covered(q) || std::fabs(distance(g[q].depth) - distance(g[i].depth)) > shader::kSsaoBlurDepthToleranceMm)
            continue;
          const double wk = std::abs(k) == 2 ? 1 : 2;
          sum += wk * ao[q];
          total += wk;
        }
        out[i] = sum / total;
      }
    ao = out;
  }
  return ao;
}

TEST_F(GpuShade, multiScaleAoIsThePapersSamplingToTheCpuReference) {
  // Interleaved bands of fibers at depths that wave by +-6 mm, with holes,
  // so pixels see occluders at every scale; white, unlit, so the image is
  // the occlusion factor. One scale of 16 samples (the default), the
  // paper's 5 scales from 3 px with 64 .. 4 samples, and 3 scales of 32.
  Camera cam = camera();
  cam.width = 72;
  cam.height = 56;
  std::vector<shader::GBufferTexel> g(size_t(cam.width) * cam.height, {1.0f, shader::kNoFiberId, 0, 0});
  for (uint32_t y = 0; y < cam.height; ++y)
    for (uint32_t x = 0; x < cam.width; ++x) {
      if ((x * 7 + y * 3) % 11 == 0) continue;
      const uint32_t fiber = 10 + y / 3 + (x / 17) * 40;
      const double mm = 95 + 6 * std::sin(0.23 * x + 1.7 * fiber) + 2 * std::cos(0.5 * y);
      g[y * cam.width + x] = {clipDepth(cam, mm), fiber, 0, packTangent({1, 0.2, 0.1})};
    }
  RenderSettings s;
  s.lighting = Lighting::None;
  s.color = ColorMode::Solid;
  s.solid_color = {1, 1, 1};
  s.ssao = true;
  s.ssao_strength = 0.9f;
  s.ssao_range_mm = 12.0f;
  struct Sampling {
    float radius;
    int scales, samples;
  };
  for (Sampling m : {Sampling{6, 1, 16}, Sampling{3, 5, 64}, Sampling{2, 3, 32}}) {
    SCOPED_TRACE("radius " + std::to_string(m.radius) + ", " + std::to_string(m.scales) + " scales, " +
                 std::to_string(m.samples) + " samples");
    s.ssao_radius_px = m.radius;
    s.ao_scales = m.scales;
    s.ao_samples = m.samples;
    const std::vector<uint8_t> rgba = shadeGBuffer(cam, g, s);
    const std::vector<double> want = referenceAo(cam, g, s);
    size_t covered = 0, close = 0, darkened = 0;
    int worst = 0;
    for (size_t i = 0; i < g.size(); ++i) {
      if (g[i].fiber == shader::kNoFiberId) continue;
      ++covered;
      const int expected = int(want[i] * 255 + 0.5), got = rgba[4 * i];
      close += std::abs(got - expected) <= 1;
      darkened += expected < 230;
      worst = std::max(worst, std::abs(got - expected));
    }
    // A sample that lands on a pixel edge may round the other way on the
    // GPU's float: a few pixels a little off, never more than one sample's
    // weight after the blur.
    EXPECT_GE(close, covered * 99 / 100) << "worst " << worst;
    EXPECT_LE(worst, 12);
    EXPECT_GT(darkened, covered / 4) << "the scene must be occluded for the test to mean anything";
  }
}

TEST_F(GpuShade, viewerSettingsOutOfRangeAreRejected) {
  RenderSettings s;
  s.scalar_min = 2.0f;
  s.scalar_max = 1.0f;
  EXPECT_THROW(shade({}, s), Error);
  s = {};
  s.scalar_max = std::numeric_limits<float>::infinity();
  EXPECT_THROW(shade({}, s), Error);
  s = {};
  s.dim_unselected = 1.5f;
  EXPECT_THROW(shade({}, s), Error);
  s = {};
  s.highlight_color = {0.5f, -0.1f, 0.5f};
  EXPECT_THROW(shade({}, s), Error);
}

TEST_F(GpuShade, wholePhantomFramesInTheViewerModesAreShadedAndTimed) {
  const Tractogram fibers = phantom(300, 5);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  constexpr uint32_t kFrame = 128;
  FrameRenderer renderer(context(), kFrame, kFrame);
  const Camera camera = standardView(tractogramBounds(fibers), StandardView::Coronal, kFrame, kFrame);
  GpuScene scene{&upload.dataset};
  scene.fiber_scalars = upload.dataset.fiberLength().address;  // colour by length, no extra upload
  GpuFiberAttributes attributes(context(), fibers.streamlineCount());
  std::vector<uint32_t> words(selectionWordCount(fibers.streamlineCount()), 0);
  for (uint32_t f = 0; f < fibers.streamlineCount(); f += 10) words[f / 32] |= 1u << (f % 32);
  attributes.uploadSelection(words);
  RenderSettings s;
  s.culling = CullingMode::None;
  s.scalar_min = 0.0f;
  s.scalar_max = 150.0f;
  s.ao_scales = 3;
  for (ColorMode mode : {ColorMode::Scalar, ColorMode::Normal})
    for (bool fxaa : {false, true})
      for (bool selection : {false, true}) {
        SCOPED_TRACE(std::string(colorModeName(mode)) + (fxaa ? " fxaa" : "") + (selection ? " selection" : ""));
        s.color = mode;
        s.fxaa = fxaa;
        scene.selection_bits = selection ? attributes.selection() : 0;
        const FrameStats stats = renderer.render(camera, s, scene);
        bool timed_fxaa = false;
        for (const PassTiming& p : stats.passes) timed_fxaa |= p.name == "fxaa";
        EXPECT_EQ(timed_fxaa, fxaa);
        const std::vector<uint8_t> rgba = downloadColor(context(), renderer.targets());
        std::set<uint32_t> colors;
        for (size_t i = 0; i < rgba.size(); i += 4)
          colors.insert(uint32_t(rgba[i]) | uint32_t(rgba[i + 1]) << 8 | uint32_t(rgba[i + 2]) << 16);
        EXPECT_GT(colors.size(), 30u);
      }
}

}  // namespace
}  // namespace fibscope
