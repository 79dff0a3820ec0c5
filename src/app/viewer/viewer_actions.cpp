#include "app/viewer/viewer_actions.h"

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
    float r = 0, g = 0, b = 0;
    char rest = 0;
    if (std::sscanf(v.c_str(), "%f,%f,%f%c", &r, &g, &b, &rest) != 3 || !(r >= 0 && r <= 1) ||
        !(g >= 0 && g <= 1) || !(b >= 0 && b <= 1))
      throw Error("set background: expected R,G,B with each in [0, 1], got '" + v + "'");
    s.background = {r, g, b};
  } else {
    throw Error("set: unknown setting '" + std::string(key) +
                "' (expected pipeline, culling, color, lighting, width, ssao or background)");
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
