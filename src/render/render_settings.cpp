#include "render/render_settings.h"

#include <string>

#include "core/error.h"

namespace fibscope {
namespace {

template <typename Enum, size_t N>
Enum parseName(std::string_view what, std::string_view name, const std::pair<std::string_view, Enum> (&names)[N]) {
  std::string accepted;
  for (const auto& [text, value] : names) {
    if (text == name) return value;
    accepted += (accepted.empty() ? "" : ", ") + std::string(text);
  }
  throw Error(std::string(what) + ": unknown value '" + std::string(name) + "' (expected one of: " + accepted + ")");
}

template <typename Enum, size_t N>
std::string_view nameOf(Enum value, const std::pair<std::string_view, Enum> (&names)[N]) {
  for (const auto& [text, v] : names)
    if (v == value) return text;
  return "?";
}

constexpr std::pair<std::string_view, RenderPipeline> kPipelines[] = {
    {"compute", RenderPipeline::Compute},   {"lines", RenderPipeline::Lines},
    {"raw-compute", RenderPipeline::RawCompute}, {"geometry", RenderPipeline::Geometry},
    {"tessellation", RenderPipeline::Tessellation}, {"mesh", RenderPipeline::Mesh},
    {"mesh-serial", RenderPipeline::MeshSerial}};
constexpr std::pair<std::string_view, CullingMode> kCulling[] = {
    {"none", CullingMode::None}, {"frustum", CullingMode::Frustum}, {"two-phase", CullingMode::TwoPhase},
    {"coverage", CullingMode::Coverage}};
constexpr std::pair<std::string_view, ColorMode> kColors[] = {
    {"solid", ColorMode::Solid}, {"orientation", ColorMode::Orientation}, {"fiber", ColorMode::PerFiber},
    {"scalar", ColorMode::Scalar}, {"normal", ColorMode::Normal}};
constexpr std::pair<std::string_view, Lighting> kLighting[] = {
    {"none", Lighting::None}, {"illuminated", Lighting::IlluminatedLines}, {"pbr", Lighting::Pbr}};
constexpr std::pair<std::string_view, Colormap> kColormaps[] = {{"viridis", Colormap::Viridis},
                                                                {"magma", Colormap::Magma},
                                                                {"grayscale", Colormap::Grayscale},
                                                                {"coolwarm", Colormap::CoolWarm}};
constexpr std::pair<std::string_view, TubeMethod> kTubeMethods[] = {
    {"compute", TubeMethod::Compute}, {"raycast", TubeMethod::Raycast}, {"tess", TubeMethod::Tessellation}};
constexpr std::pair<std::string_view, AoMethod> kAoMethods[] = {{"ssao", AoMethod::Ssao}, {"df", AoMethod::Df}};

constexpr std::pair<std::string_view, SliceSampling> kSamplings[] = {{"trilinear", SliceSampling::Trilinear},
                                                                   {"nearest", SliceSampling::Nearest}};
constexpr std::pair<std::string_view, SliceAxis> kSliceAxes[] = {
    {"i", SliceAxis::I}, {"j", SliceAxis::J}, {"k", SliceAxis::K}};

}  // namespace

float slicePosition(const RenderSettings& s, int axis) {
  return axis == 0 ? s.slice_i : (axis == 1 ? s.slice_j : s.slice_k);
}

void setSlicePosition(RenderSettings& s, int axis, float position) {
  (axis == 0 ? s.slice_i : (axis == 1 ? s.slice_j : s.slice_k)) = position;
}

RenderPipeline parseRenderPipeline(std::string_view name) { return parseName("pipeline", name, kPipelines); }
CullingMode parseCullingMode(std::string_view name) { return parseName("culling", name, kCulling); }
ColorMode parseColorMode(std::string_view name) { return parseName("color", name, kColors); }
Lighting parseLighting(std::string_view name) { return parseName("lighting", name, kLighting); }
Colormap parseColormap(std::string_view name) { return parseName("colormap", name, kColormaps); }
TubeMethod parseTubeMethod(std::string_view name) { return parseName("tube-method", name, kTubeMethods); }
std::string_view tubeMethodName(TubeMethod method) { return nameOf(method, kTubeMethods); }
AoMethod parseAoMethod(std::string_view name) { return parseName("ao-method", name, kAoMethods); }
std::string_view aoMethodName(AoMethod method) { return nameOf(method, kAoMethods); }
std::string_view sliceSamplingName(SliceSampling sampling) { return nameOf(sampling, kSamplings); }
std::string_view sliceAxisName(SliceAxis axis) { return nameOf(axis, kSliceAxes); }
std::string_view renderPipelineName(RenderPipeline pipeline) { return nameOf(pipeline, kPipelines); }
std::string_view cullingModeName(CullingMode mode) { return nameOf(mode, kCulling); }
std::string_view colorModeName(ColorMode mode) { return nameOf(mode, kColors); }
std::string_view lightingName(Lighting lighting) { return nameOf(lighting, kLighting); }
std::string_view colormapName(Colormap colormap) { return nameOf(colormap, kColormaps); }

}  // namespace fibscope
