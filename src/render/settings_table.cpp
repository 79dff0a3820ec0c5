#include "render/settings_table.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.h"
#include "render/colormap.h"
#include "render/reference_raster.h"
#include "shared/distance_field.h"
#include "shared/shade_push.h"

namespace fibscope {
namespace {

// Choice accessors for an enum member.
template <typename Enum, Enum RenderSettings::*member>
int getChoice(const RenderSettings& s) {
  return int(s.*member);
}
template <typename Enum, Enum RenderSettings::*member>
void setChoice(RenderSettings& s, int v) {
  s.*member = Enum(v);
}

SettingInfo entry(std::string_view name, std::string_view label, std::string_view help, SettingKind kind) {
  SettingInfo i;
  i.name = name;
  i.label = label;
  i.help = help;
  i.kind = kind;
  return i;
}

SettingInfo choice(std::string_view name, std::string_view label, std::string_view help, int count,
                   std::string_view (*name_of)(int), int (*get)(const RenderSettings&),
                   void (*set)(RenderSettings&, int)) {
  SettingInfo i = entry(name, label, help, SettingKind::Choice);
  i.choice_count = count;
  i.choice_name = name_of;
  i.get_choice = get;
  i.set_choice = set;
  return i;
}

SettingInfo number(std::string_view name, std::string_view label, std::string_view help, float RenderSettings::*m,
                   double lo, double hi, std::string_view unit = {}) {
  SettingInfo i = entry(name, label, help, SettingKind::Number);
  i.number = m;
  i.min = lo;
  i.max = hi;
  i.unit = unit;
  return i;
}

SettingInfo integer(std::string_view name, std::string_view label, std::string_view help, int RenderSettings::*m,
                    double lo, double hi) {
  SettingInfo i = entry(name, label, help, SettingKind::Integer);
  i.integer = m;
  i.min = lo;
  i.max = hi;
  return i;
}

SettingInfo flag(std::string_view name, std::string_view label, std::string_view help, bool RenderSettings::*m) {
  SettingInfo i = entry(name, label, help, SettingKind::Flag);
  i.flag = m;
  return i;
}

SettingInfo color(std::string_view name, std::string_view label, std::string_view help,
                  std::array<float, 3> RenderSettings::*m) {
  SettingInfo i = entry(name, label, help, SettingKind::Color);
  i.color = m;
  i.min = 0;
  i.max = 1;
  return i;
}

template <typename T>
T&& with(T&& info, bool (*relevant)(const RenderSettings&)) {
  info.relevant = relevant;
  return std::forward<T>(info);
}

// Slice positions are voxel coordinates: NIfTI allows 2^24 voxels a side,
// an anatomical volume far fewer; the viewer's sliders span the volume.
constexpr double kMaxSliceCoordinate = 1e6;

bool isFiblets(const RenderSettings& s) { return drawsFiblets(s.pipeline); }
// The far-view LoD is the compute pipeline's (the graphics fiblet pipelines
// draw every culled-in fiblet at full detail).
bool isCulled(const RenderSettings& s) {
  return (s.pipeline == RenderPipeline::Compute || needsMeshShaders(s.pipeline)) && s.culling != CullingMode::None;
}
bool isCoverage(const RenderSettings& s) { return s.pipeline == RenderPipeline::Compute && s.culling == CullingMode::Coverage; }
bool isSolid(const RenderSettings& s) { return s.color == ColorMode::Solid; }
bool isScalar(const RenderSettings& s) { return s.color == ColorMode::Scalar; }
bool isLit(const RenderSettings& s) { return s.lighting == Lighting::IlluminatedLines; }
bool isPbr(const RenderSettings& s) { return s.lighting == Lighting::Pbr; }
bool hasAmbient(const RenderSettings& s) { return s.lighting != Lighting::None; }
bool hasSsao(const RenderSettings& s) { return s.ssao && s.ao_method == AoMethod::Ssao; }
bool hasAo(const RenderSettings& s) { return s.ssao; }
bool hasDfAo(const RenderSettings& s) { return s.ssao && s.ao_method == AoMethod::Df; }
bool hasDfShadows(const RenderSettings& s) { return s.df_shadows; }
bool isTessellatedTubes(const RenderSettings& s) { return s.tube_method == TubeMethod::Tessellation; }

std::vector<SettingInfo> makeTable() {
  std::vector<SettingInfo> t;
  t.push_back(choice("pipeline", "pipeline", "compute | lines | raw-compute | geometry | tessellation | mesh | mesh-serial (mesh: VK_EXT_mesh_shader)", 7,
                     [](int v) { return renderPipelineName(RenderPipeline(v)); },
                     getChoice<RenderPipeline, &RenderSettings::pipeline>,
                     setChoice<RenderPipeline, &RenderSettings::pipeline>));
  t.push_back(with(choice("culling", "culling",
                          "none | frustum | two-phase (fiblet pipelines: compute, geometry, tessellation, mesh, "
                          "mesh-serial) | coverage (compute pipeline)",
                          4,
                          [](int v) { return cullingModeName(CullingMode(v)); },
                          getChoice<CullingMode, &RenderSettings::culling>,
                          setChoice<CullingMode, &RenderSettings::culling>),
                   isFiblets));
  t.push_back(with(number("lod-pixels", "LoD below",
                          "Far-view LoD: fiblets whose bounding sphere projects smaller are drawn as one segment "
                          "(frustum, two-phase and coverage culling; 0: off)",
                          &RenderSettings::lod_pixels, 0, 4096, "px"),
                   isCulled));
  t.push_back(with(number("coverage-splat", "coverage splat",
                          "Coverage culling: the radius of each re-projected sample's hemisphere in previous-frame "
                          "pixels (0.71: exact with the camera still; larger culls more and misses more)",
                          &RenderSettings::coverage_splat_px, 0.5f, 8, "px"),
                   isCoverage));
  SettingInfo width = number("line-width", "line width", "Line width in pixels", &RenderSettings::line_width_px,
                             kMinLineWidth, kMaxLineWidth, "px");
  width.alias = "width";
  t.push_back(width);
  t.push_back(choice("color", "colour", "orientation | solid | fiber | scalar (fiber length) | normal", 5,
                     [](int v) { return colorModeName(ColorMode(v)); }, getChoice<ColorMode, &RenderSettings::color>,
                     setChoice<ColorMode, &RenderSettings::color>));
  t.push_back(with(color("solid-color", "solid colour", "The solid colour R,G,B in [0, 1] (--color solid)",
                         &RenderSettings::solid_color),
                   isSolid));
  t.push_back(with(choice("colormap", "colormap", "viridis | magma | grayscale | coolwarm (--color scalar)", 4,
                          [](int v) { return colormapName(Colormap(v)); },
                          getChoice<Colormap, &RenderSettings::colormap>,
                          setChoice<Colormap, &RenderSettings::colormap>),
                   isScalar));
  SettingInfo range = entry("scalar-range", "range", "MIN,MAX mapped onto the colormap (default: the data's range)",
                            SettingKind::Range);
  range.number = &RenderSettings::scalar_min;
  range.number_max = &RenderSettings::scalar_max;
  range.min = -1e30;
  range.max = 1e30;
  range.relevant = isScalar;
  t.push_back(range);
  t.push_back(color("highlight", "highlight", "Colour of selected fibers R,G,B in [0, 1]",
                    &RenderSettings::highlight_color));
  t.push_back(number("dim", "dim unselected",
                     "How far unselected fibers fade towards the background when there is a selection (0: not, "
                     "1: invisible)",
                     &RenderSettings::dim_unselected, 0, 1));
  t.push_back(choice("lighting", "lighting", "illuminated | none | pbr (Cook-Torrance under a ring of 30 lights)", 3,
                     [](int v) { return lightingName(Lighting(v)); }, getChoice<Lighting, &RenderSettings::lighting>,
                     setChoice<Lighting, &RenderSettings::lighting>));
  t.push_back(with(number("ambient", "ambient", "Ambient light coefficient", &RenderSettings::light_ambient, 0, 4),
                   hasAmbient));
  t.push_back(with(number("diffuse", "diffuse", "Diffuse light coefficient", &RenderSettings::light_diffuse, 0, 4),
                   isLit));
  t.push_back(
      with(number("specular", "specular", "Specular light coefficient", &RenderSettings::light_specular, 0, 4),
           isLit));
  t.push_back(with(number("shininess", "shininess", "Specular exponent", &RenderSettings::light_shininess, 1, 256),
                   isLit));
  t.push_back(with(number("roughness", "roughness", "PBR surface roughness (GGX; 0.05 to 1)",
                          &RenderSettings::pbr_roughness, 0.05, 1),
                   isPbr));
  t.push_back(with(number("metalness", "metalness", "PBR metalness (0: dielectric, 1: metal)",
                          &RenderSettings::pbr_metalness, 0, 1),
                   isPbr));
  t.push_back(with(number("light-intensity", "light intensity", "PBR: total radiance of the ring of lights",
                          &RenderSettings::pbr_intensity, 0, 64),
                   isPbr));
  t.push_back(flag("ssao", "ambient occlusion", "Ambient occlusion (by --ao-method)", &RenderSettings::ssao));
  t.push_back(with(choice("ao-method", "AO method",
                          "ssao (screen space) | df (Evans' distance-field AO from the tubes' distance field: "
                          "frames with tubes or an svo pipeline)",
                          2, [](int v) { return aoMethodName(AoMethod(v)); },
                          getChoice<AoMethod, &RenderSettings::ao_method>,
                          setChoice<AoMethod, &RenderSettings::ao_method>),
                   hasAo));
  t.push_back(with(number("ssao-radius", "AO radius", "SSAO sampling radius in pixels (the smallest scale)",
                          &RenderSettings::ssao_radius_px, 1, 64, "px"),
                   hasSsao));
  t.push_back(with(number("ssao-strength", "AO strength", "How dark full occlusion gets (0 to 1)",
                          &RenderSettings::ssao_strength, 0, 1),
                   hasSsao));
  SettingInfo scales = entry("ao-scales", "AO scales",
                             "Multi-scale AO: 1 to 5 radii (r, 2r, 4r, 8r, 16r; the paper: radius 3, 5 scales)",
                             SettingKind::Integer);
  scales.integer = &RenderSettings::ao_scales;
  scales.min = 1;
  scales.max = shader::kSsaoMaxScales;
  scales.relevant = hasSsao;
  t.push_back(scales);
  SettingInfo samples = entry("ao-samples", "AO samples",
                              "AO samples at the smallest scale, halved at each larger one (the paper: 64)",
                              SettingKind::Integer);
  samples.integer = &RenderSettings::ao_samples;
  samples.min = shader::kSsaoMinSamples;
  samples.max = shader::kSsaoMaxSamples;
  samples.relevant = hasSsao;
  t.push_back(samples);
  t.push_back(with(number("ssao-range", "AO range",
                          "Neighbours nearer than this (view distance) no longer occlude, in mm",
                          &RenderSettings::ssao_range_mm, 0.5, 200, "mm"),
                   hasSsao));
  // The tubes' distance field (shared/distance_field.h): AO and shadows.
  t.push_back(number("df-voxel", "DF voxel",
                     "Voxel of the tubes' distance field (AO and shadows), mm; 0: the largest tube radius, "
                     "coarsened until the field is at most 64 MB (read when the field is built)",
                     &RenderSettings::df_voxel_mm, 0, 100, "mm"));
  t.push_back(with(integer("df-ao-steps", "DF AO steps", "Distance-field AO: samples N along the normal",
                           &RenderSettings::df_ao_steps, 1, shader::kDfMaxAoSteps),
                   hasDfAo));
  t.push_back(with(number("df-ao-delta", "DF AO step",
                          "Distance-field AO: spacing delta of the samples, mm (0: the field's voxel; the reach "
                          "N delta is capped at 8 voxels)",
                          &RenderSettings::df_ao_delta_mm, 0, 100, "mm"),
                   hasDfAo));
  t.push_back(with(number("df-ao-strength", "DF AO strength",
                          "Distance-field AO: k in 1 - (k / delta) sum 2^-i (h_i - d_i)", &RenderSettings::df_ao_strength,
                          0, 8),
                   hasDfAo));
  t.push_back(flag("df-shadows", "DF shadows",
                   "Soft shadows from the headlight, sphere-traced through the tubes' distance field (frames with "
                   "tubes or an svo pipeline)",
                   &RenderSettings::df_shadows));
  t.push_back(with(number("df-shadow-softness", "shadow hardness",
                          "Soft shadows: k_s in min(k_s d / t) (larger: harder penumbrae)",
                          &RenderSettings::df_shadow_softness, 0.5, 128),
                   hasDfShadows));
  // Post effects, in the order they apply (after AO, before FXAA).
  SettingInfo flatten = entry("flatten", "flatten",
                              "Colour flattening to N levels a channel (2 to 256; 0 or 1: off)", SettingKind::Integer);
  flatten.integer = &RenderSettings::flatten_levels;
  flatten.min = 0;
  flatten.max = 256;
  t.push_back(flatten);
  t.push_back(number("contrast", "contrast", "Contrast: (c - 0.5) C + 0.5 (1: off)", &RenderSettings::contrast, 0, 4));
  t.push_back(number("brightness", "brightness", "Brightness: c + D (0: off)", &RenderSettings::brightness, -1, 1));
  t.push_back(number("saturation", "saturation",
                     "Saturation: L + S (c - L), L = 0.2125 R + 0.7154 G + 0.0721 B (0: grey, 1: off)",
                     &RenderSettings::saturation, 0, 4));
  t.push_back(number("sharpen", "sharpen",
                     "Sharpening by the 3x3 kernel [0 -S 0; -S 1+4S -S; 0 -S 0] (0: off)", &RenderSettings::sharpen,
                     0, 4));
  t.push_back(flag("fxaa", "FXAA", "Fast approximate anti-aliasing of the image", &RenderSettings::fxaa));
  t.push_back(color("background", "background", "Background colour R,G,B in [0, 1]", &RenderSettings::background));
  t.push_back(number("slab", "slab",
                     "Draw only a slab this thick around the focal plane (moving with the view), or around the "
                     "active anatomical slice with --slab-follows-slice, mm; 0: off",
                     &RenderSettings::slab_mm, 0, 1000, "mm"));
  t.push_back(flag("orientation-labels", "orientation labels",
                   "L/R, A/P, S/I at the image's edges and an axis triad (x red, y green, z blue) in a corner",
                   &RenderSettings::orientation_labels));
  // Anatomical slices (--anatomy; the viewer's anatomy panel).
  auto anatomy = [&](SettingInfo info) {
    info.group = "anatomy";
    t.push_back(info);
  };
  anatomy(number("slice-i", "slice i",
                 "The slice along the volume's first voxel axis at this voxel coordinate (voxel centres at "
                 "integers; unless given, the volume's centre)",
                 &RenderSettings::slice_i, 0, kMaxSliceCoordinate));
  anatomy(number("slice-j", "slice j", "The same along the second voxel axis", &RenderSettings::slice_j, 0,
                 kMaxSliceCoordinate));
  anatomy(number("slice-k", "slice k", "The same along the third voxel axis", &RenderSettings::slice_k, 0,
                 kMaxSliceCoordinate));
  anatomy(flag("show-slice-i", "show i", "Anatomical slice along the first voxel axis", &RenderSettings::show_slice_i));
  anatomy(flag("show-slice-j", "show j", "Anatomical slice along the second voxel axis", &RenderSettings::show_slice_j));
  anatomy(flag("show-slice-k", "show k", "Anatomical slice along the third voxel axis", &RenderSettings::show_slice_k));
  anatomy(choice("active-slice", "active slice", "i | j | k: the slice the viewer's Page Up/Down move and the slab "
                 "follows", 3, [](int v) { return sliceAxisName(SliceAxis(v)); },
                 getChoice<SliceAxis, &RenderSettings::active_slice>,
                 setChoice<SliceAxis, &RenderSettings::active_slice>));
  SettingInfo window = entry("anatomy-range", "display range",
                             "MIN,MAX of the volume's values shown black to white (unless given, its 2nd to 98th "
                             "percentile)",
                             SettingKind::Range);
  window.number = &RenderSettings::anatomy_min;
  window.number_max = &RenderSettings::anatomy_max;
  window.min = -1e30;
  window.max = 1e30;
  anatomy(window);
  anatomy(number("anatomy-opacity", "opacity",
                 "Opacity of the slices: 1 hides the fibers behind them, below 1 they show through; 0: no slices",
                 &RenderSettings::anatomy_opacity, 0, 1));
  anatomy(choice("anatomy-sampling", "sampling", "trilinear (as mrview) | nearest (the voxels as they are)", 2,
                 [](int v) { return sliceSamplingName(SliceSampling(v)); },
                 getChoice<SliceSampling, &RenderSettings::anatomy_sampling>,
                 setChoice<SliceSampling, &RenderSettings::anatomy_sampling>));
  anatomy(flag("slab-follows-slice", "slab follows slice",
               "The slab (--slab) lies around the active anatomical slice instead of the focal plane",
               &RenderSettings::slab_follows_slice));
  // Spline tubes (the viewer's tubes panel; render and bench with --tubes).
  auto tubes = [&](SettingInfo info) {
    info.group = "tubes";
    t.push_back(info);
  };
  tubes(choice("tube-method", "method",
               "compute (ray casting in compute, tiles: lavapipe, compute-only GPUs) | raycast (ray casting in the "
               "fragment shader, one box per sub-segment) | tess (tessellated cylinders)",
               3, [](int v) { return tubeMethodName(TubeMethod(v)); },
               getChoice<TubeMethod, &RenderSettings::tube_method>, setChoice<TubeMethod, &RenderSettings::tube_method>));
  tubes(with(integer("tube-rings", "rings", "Tessellated tubes: rings of the base mesh per segment before refinement",
                     &RenderSettings::tube_rings, 2, 64),
             isTessellatedTubes));
  tubes(with(integer("tube-vertices", "vertices", "Tessellated tubes: vertices per ring of the base mesh",
                     &RenderSettings::tube_vertices, 3, 64),
             isTessellatedTubes));
  tubes(with(choice("tube-msaa", "MSAA", "Tessellated tubes: samples per pixel, 1 | 4 | 8", 3,
                    [](int v) { return std::string_view(v == 0 ? "1" : (v == 1 ? "4" : "8")); },
                    [](const RenderSettings& s) {
                      return s.tube_msaa == 8 ? 2 : (s.tube_msaa == 4 ? 1 : (s.tube_msaa == 1 ? 0 : -1));
                    },
                    // Outside the names: 0 samples, which validation rejects.
                    [](RenderSettings& s, int v) { s.tube_msaa = v == 0 ? 1 : (v == 1 ? 4 : (v == 2 ? 8 : 0)); }),
             isTessellatedTubes));
  return t;
}

bool parseDouble(std::string_view text, double& out) {
  const char* end = text.data() + text.size();
  auto [p, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && p == end && std::isfinite(out);
}

// "A,B[,C]": exactly `n` finite numbers.
bool parseList(std::string_view text, double* out, int n) {
  for (int k = 0; k < n; ++k) {
    const size_t comma = k + 1 < n ? text.find(',') : std::string_view::npos;
    if (k + 1 < n && comma == std::string_view::npos) return false;
    if (!parseDouble(text.substr(0, comma), out[k])) return false;
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
  }
  return true;
}

std::string formatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string withUnit(const SettingInfo& info, double lo, double hi) {
  return formatNumber(lo) + " to " + formatNumber(hi) + (info.unit.empty() ? "" : " " + std::string(info.unit));
}

bool inRange(const SettingInfo& info, double v) { return v >= info.min && v <= info.max; }  // false for NaN

}  // namespace

std::span<const SettingInfo> renderSettingsTable() {
  static const std::vector<SettingInfo> table = makeTable();
  return table;
}

const SettingInfo* findSetting(std::string_view name) {
  for (const SettingInfo& s : renderSettingsTable())
    if (s.name == name || (!s.alias.empty() && s.alias == name)) return &s;
  return nullptr;
}

std::string settingExpectation(const SettingInfo& info) {
  switch (info.kind) {
    case SettingKind::Flag: return "on or off";
    case SettingKind::Integer:
    case SettingKind::Number: return withUnit(info, info.min, info.max);
    case SettingKind::Choice: {
      std::string names;
      for (int i = 0; i < info.choice_count; ++i) names += (i ? ", " : "") + std::string(info.choice_name(i));
      return "one of: " + names;
    }
    case SettingKind::Color: return "R,G,B with each in [0, 1]";
    case SettingKind::Range: return "MIN,MAX (finite, MIN <= MAX)";
  }
  return {};
}

void setSetting(RenderSettings& s, const SettingInfo& info, std::string_view text, std::string_view where) {
  auto bad = [&]() -> Error {
    return Error(std::string(where) + ": expected " + settingExpectation(info) + ", got '" + std::string(text) + "'");
  };
  switch (info.kind) {
    case SettingKind::Flag:
      if (text != "on" && text != "off") throw bad();
      s.*info.flag = text == "on";
      return;
    case SettingKind::Integer: {
      double v = 0;
      if (!parseDouble(text, v) || v != std::floor(v) || !inRange(info, v)) throw bad();
      s.*info.integer = int(v);
      return;
    }
    case SettingKind::Number: {
      double v = 0;
      if (!parseDouble(text, v) || !inRange(info, v)) throw bad();
      s.*info.number = float(v);
      return;
    }
    case SettingKind::Choice:
      for (int i = 0; i < info.choice_count; ++i)
        if (info.choice_name(i) == text) {
          info.set_choice(s, i);
          return;
        }
      throw bad();
    case SettingKind::Color: {
      double c[3];
      if (!parseList(text, c, 3)) throw bad();
      for (double v : c)
        if (!(v >= 0 && v <= 1)) throw bad();
      s.*info.color = {float(c[0]), float(c[1]), float(c[2])};
      return;
    }
    case SettingKind::Range: {
      double r[2];
      if (!parseList(text, r, 2) || !(r[0] <= r[1]) || !inRange(info, r[0]) || !inRange(info, r[1])) throw bad();
      s.*info.number = float(r[0]);
      s.*info.number_max = float(r[1]);
      return;
    }
  }
}

std::string settingText(const RenderSettings& s, const SettingInfo& info) {
  switch (info.kind) {
    case SettingKind::Flag: return s.*info.flag ? "on" : "off";
    case SettingKind::Integer: return std::to_string(s.*info.integer);
    case SettingKind::Number: return formatNumber(s.*info.number);
    case SettingKind::Choice: return std::string(info.choice_name(info.get_choice(s)));
    case SettingKind::Color: {
      const std::array<float, 3>& c = s.*info.color;
      return formatNumber(c[0]) + "," + formatNumber(c[1]) + "," + formatNumber(c[2]);
    }
    case SettingKind::Range: return formatNumber(s.*info.number) + "," + formatNumber(s.*info.number_max);
  }
  return {};
}

void validateRenderSettings(const RenderSettings& s) {
  for (const SettingInfo& info : renderSettingsTable()) {
    bool ok = true;
    switch (info.kind) {
      case SettingKind::Flag: break;
      case SettingKind::Integer: ok = inRange(info, s.*info.integer); break;
      case SettingKind::Number: ok = inRange(info, s.*info.number); break;
      case SettingKind::Choice: ok = info.get_choice(s) >= 0 && info.get_choice(s) < info.choice_count; break;
      case SettingKind::Color:
        for (float v : s.*info.color) ok &= v >= 0.0f && v <= 1.0f;
        break;
      case SettingKind::Range:
        ok = inRange(info, s.*info.number) && inRange(info, s.*info.number_max) && s.*info.number <= s.*info.number_max;
        break;
    }
    if (!ok)
      throw Error("render: " + std::string(info.label) + " must be " + settingExpectation(info) + ", got " +
                  (info.kind == SettingKind::Choice ? std::to_string(info.get_choice(s)) : settingText(s, info)));
  }
}

}  // namespace fibscope
