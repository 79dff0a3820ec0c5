#include "render/colormap.h"

#include <algorithm>
#include <cmath>

namespace fibscope {
namespace {

using Rgb = std::array<float, 3>;

// matplotlib's viridis at t = 0, 0.1, ..., 1 (rounded to 3 decimals).
constexpr Rgb kViridis[] = {{0.267f, 0.005f, 0.329f}, {0.283f, 0.141f, 0.458f}, {0.254f, 0.265f, 0.530f},
                                {0.207f, 0.372f, 0.553f}, {0.164f, 0.471f, 0.558f}, {0.128f, 0.567f, 0.551f},
                                {0.135f, 0.659f, 0.518f}, {0.267f, 0.749f, 0.441f}, {0.478f, 0.821f, 0.318f},
                                {0.741f, 0.873f, 0.150f}, {0.993f, 0.906f, 0.144f}};
// matplotlib's magma at t = 0, 0.1, ..., 1.
constexpr Rgb kMagma[] = {{0.001f, 0.000f, 0.014f}, {0.082f, 0.060f, 0.231f}, {0.232f, 0.060f, 0.438f},
                          {0.390f, 0.100f, 0.502f}, {0.550f, 0.161f, 0.506f}, {0.716f, 0.215f, 0.475f},
                          {0.868f, 0.288f, 0.409f}, {0.967f, 0.439f, 0.360f}, {0.995f, 0.624f, 0.427f},
                          {0.996f, 0.812f, 0.573f}, {0.987f, 0.991f, 0.750f}};
constexpr Rgb kGrayscale[] = {{0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}};
// Moreland's cool-warm (his table's 0, 0.25, 0.5, 0.75, 1 entries): the
// Msh path between (59, 76, 192) and (180, 4, 38) through a neutral grey.
constexpr Rgb kCoolWarm[] = {{0.230f, 0.299f, 0.754f}, {0.552f, 0.690f, 0.996f}, {0.865f, 0.865f, 0.865f},
                             {0.958f, 0.603f, 0.482f}, {0.706f, 0.016f, 0.150f}};

}  // namespace

std::span<const std::array<float, 3>> colormapControlPoints(Colormap colormap) {
  switch (colormap) {
    case Colormap::Viridis: return kViridis;
    case Colormap::Magma: return kMagma;
    case Colormap::Grayscale: return kGrayscale;
    case Colormap::CoolWarm: return kCoolWarm;
  }
  return kGrayscale;
}

std::array<float, 3> colormapColor(Colormap colormap, float t) {
  const auto points = colormapControlPoints(colormap);
  if (!(t > 0.0f)) return points.front();  // also NaN
  if (t >= 1.0f) return points.back();
  const float x = t * float(points.size() - 1);
  const size_t k = std::min(size_t(x), points.size() - 2);
  const float f = x - float(k);
  Rgb c{};
  for (int i = 0; i < 3; ++i) c[i] = points[k][i] + f * (points[k + 1][i] - points[k][i]);
  return c;
}

std::vector<uint32_t> colormapTable(Colormap colormap) {
  std::vector<uint32_t> table(kColormapEntries);
  for (uint32_t i = 0; i < kColormapEntries; ++i) {
    const Rgb c = colormapColor(colormap, float(i) / float(kColormapEntries - 1));
    uint32_t packed = 0xFF000000u;
    for (int k = 0; k < 3; ++k) packed |= uint32_t(std::lround(std::clamp(c[k], 0.0f, 1.0f) * 255.0f)) << (8 * k);
    table[i] = packed;
  }
  return table;
}

std::vector<uint32_t> allColormapTables() {
  std::vector<uint32_t> all;
  all.reserve(kColormapCount * kColormapEntries);
  for (uint32_t c = 0; c < kColormapCount; ++c) {
    const std::vector<uint32_t> table = colormapTable(Colormap(c));
    all.insert(all.end(), table.begin(), table.end());
  }
  return all;
}

uint32_t colormapIndex(float value, float scalar_min, float scalar_max) {
  float t = 0.5f;
  if (scalar_max > scalar_min) t = (value - scalar_min) / (scalar_max - scalar_min);
  if (std::isnan(value)) t = 0.0f;
  t = std::clamp(t, 0.0f, 1.0f);
  return uint32_t(t * float(kColormapEntries - 1) + 0.5f);
}

bool finiteRange(std::span<const float> values, float& lo, float& hi) {
  float low = INFINITY, high = -INFINITY;
  for (float v : values)
    if (std::isfinite(v)) {
      low = std::min(low, v);
      high = std::max(high, v);
    }
  if (low > high) return false;
  lo = low;
  hi = high;
  return true;
}

}  // namespace fibscope
