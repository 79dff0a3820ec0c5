#include "app/viewer/viewer_actions.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.h"
#include "render/reference_raster.h"

namespace fibscope {
namespace {

bool parseFloat(std::string_view text, float& value) {
  const std::string s(text);
  char rest = 0;
  return std::sscanf(s.c_str(), "%f%c", &value, &rest) == 1;
}

// "R,G,B" with each in [0, 1].
std::array<float, 3> parseColor(const std::string& what, const std::string& text) {
  float r = 0, g = 0, b = 0;
  char rest = 0;
  if (std::sscanf(text.c_str(), "%f,%f,%f%c", &r, &g, &b, &rest) != 3 || !(r >= 0 && r <= 1) ||
      !(g >= 0 && g <= 1) || !(b >= 0 && b <= 1))
    throw Error(what + ": expected R,G,B with each in [0, 1], got '" + text + "'");
  return {r, g, b};
}

}  // namespace

void applySetting(RenderSettings& settings, std::string_view key, std::string_view value) {
  RenderSettings s = settings;
  const std::string v(value);
  if (key == "pipeline") {
    s.pipeline = parseRenderPipeline(value);
  } else if (key == "culling") {
    s.culling = parseCullingMode(value);
  } else if (key == "color") {
    s.color = parseColorMode(value);
  } else if (key == "lighting") {
    s.lighting = parseLighting(value);
  } else if (key == "width") {
    float w = 0;
    if (!parseFloat(value, w) || !(w >= kMinLineWidth && w <= kMaxLineWidth))
      throw Error("set width: expected a line width of 1 to 4 pixels, got '" + v + "'");
    s.line_width_px = w;
  } else if (key == "ssao") {
    if (value != "on" && value != "off") throw Error("set ssao: expected on or off, got '" + v + "'");
    s.ssao = value == "on";
  } else if (key == "background") {
    s.background = parseColor("set background", v);
  } else if (key == "colormap") {
    s.colormap = parseColormap(value);
  } else if (key == "scalar-range") {
    float lo = 0, hi = 0;
    char rest = 0;
    if (std::sscanf(v.c_str(), "%f,%f%c", &lo, &hi, &rest) != 2 || !std::isfinite(lo) || !std::isfinite(hi) ||
        lo > hi)
      throw Error("set scalar-range: expected MIN,MAX (finite, MIN <= MAX), got '" + v + "'");
    s.scalar_min = lo;
    s.scalar_max = hi;
  } else if (key == "ao-scales") {
    float n = 0;
    if (!parseFloat(value, n) || !(n >= 1 && n <= 4) || n != float(int(n)))
      throw Error("set ao-scales: expected 1, 2, 3 or 4, got '" + v + "'");
    s.ao_scales = int(n);
  } else if (key == "ssao-radius") {
    float r = 0;
    if (!parseFloat(value, r) || !(r >= 1 && r <= 64)) throw Error("set ssao-radius: expected 1 to 64 pixels, got '" + v + "'");
    s.ssao_radius_px = r;
  } else if (key == "ssao-strength") {
    float k = 0;
    if (!parseFloat(value, k) || !(k >= 0 && k <= 1)) throw Error("set ssao-strength: expected 0 to 1, got '" + v + "'");
    s.ssao_strength = k;
  } else if (key == "fxaa") {
    if (value != "on" && value != "off") throw Error("set fxaa: expected on or off, got '" + v + "'");
    s.fxaa = value == "on";
  } else if (key == "dim") {
    float d = 0;
    if (!parseFloat(value, d) || !(d >= 0 && d <= 1)) throw Error("set dim: expected 0 to 1, got '" + v + "'");
    s.dim_unselected = d;
  } else if (key == "highlight") {
    s.highlight_color = parseColor("set highlight", v);
  } else {
    throw Error("set: unknown setting '" + std::string(key) +
                "' (expected pipeline, culling, color, colormap, scalar-range, lighting, width, ssao, ssao-radius, "
                "ssao-strength, ao-scales, fxaa, background, highlight or dim)");
  }
  settings = s;
}

ViewAction parseViewName(std::string_view name) {
  if (name == "sagittal") return {StandardView::Sagittal};
  if (name == "coronal") return {StandardView::Coronal};
  if (name == "axial") return {StandardView::Axial};
  if (name == "reset") return {std::nullopt};
  throw Error("view: expected sagittal, coronal, axial or reset, got '" + std::string(name) + "'");
}

}  // namespace fibscope
