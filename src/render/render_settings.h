// What a frame is drawn with: the plain settings the command line and the
// viewer's panels edit (STYLE.md rule 10), and the statistics a frame
// reports. No Vulkan here.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace fibscope {

// Which pipeline draws the G-buffer (DESIGN.md section 6).
enum class RenderPipeline : uint8_t {
  Compute,     // fiblets: cull -> decode + raster (64-bit atomics) -> resolve
  Lines,       // baseline: raw float vertices as line strips, graphics pipeline, no culling
  RawCompute,  // baseline: the compute raster over raw float vertices, no culling
};

// Fiblet culling in the compute pipeline (the baselines never cull).
enum class CullingMode : uint8_t {
  None,      // every fiblet is drawn, no LoD
  Frustum,   // dilated frustum (paper eq. 5) and far-view LoD
  TwoPhase,  // Frustum + conservative two-phase occlusion culling
};

enum class ColorMode : uint8_t {
  Solid,        // RenderSettings::solid_color
  Orientation,  // |tangent| as RGB (world axes: x red, y green, z blue)
  PerFiber,     // a distinct colour per fiber (hashed from its index)
};

enum class Lighting : uint8_t {
  None,
  IlluminatedLines,  // Zoeckler / Stalling / Hege: diffuse and specular from the tangent alone
};

struct RenderSettings {
  RenderPipeline pipeline = RenderPipeline::Compute;
  CullingMode culling = CullingMode::TwoPhase;
  float lod_pixels = 4.0f;  // far-view LoD below this projected fiblet size (Frustum, TwoPhase)
  float line_width_px = 1.0f;  // [1, 4]
  ColorMode color = ColorMode::Orientation;
  std::array<float, 3> solid_color = {0.9f, 0.9f, 0.85f};
  Lighting lighting = Lighting::IlluminatedLines;
  // Illuminated lines: colour = base * (ambient + diffuse * D) + specular * S^shininess
  // (shaders/shared/shade_push.h).
  float light_ambient = 0.2f;
  float light_diffuse = 0.8f;
  float light_specular = 0.5f;
  float light_shininess = 48.0f;
  bool ssao = true;
  float ssao_radius_px = 10.0f;
  float ssao_strength = 0.8f;
  // Neighbours nearer than this (view distance, mm) no longer occlude: a
  // bundle far in front of another casts no shadow on it, one lying on it
  // (bundles are about 10 mm thick) does.
  float ssao_range_mm = 10.0f;
  std::array<float, 3> background = {0.0f, 0.0f, 0.0f};
};

// Parsing and names for the command line ("compute", "two-phase", ...).
// parse* throw Error listing the accepted names.
RenderPipeline parseRenderPipeline(std::string_view name);
CullingMode parseCullingMode(std::string_view name);
ColorMode parseColorMode(std::string_view name);
Lighting parseLighting(std::string_view name);
std::string_view renderPipelineName(RenderPipeline pipeline);
std::string_view cullingModeName(CullingMode mode);
std::string_view colorModeName(ColorMode mode);
std::string_view lightingName(Lighting lighting);

// GPU time of one pass of a frame.
struct PassTiming {
  std::string name;
  double ms = 0;
};

struct FrameStats {
  std::vector<PassTiming> passes;  // in recording order
  double gpu_ms = 0;               // sum of the passes
  uint64_t fiblets_total = 0;      // compute pipeline: fiblets in the dataset
  uint64_t fiblets_drawn = 0;      // ... drawn at full detail (both phases)
  uint64_t fiblets_lod = 0;        // ... drawn as one segment (far-view LoD)
  uint64_t segments_total = 0;     // segments in the dataset (every pipeline)
  uint64_t covered_pixels = 0;     // pixels with a fiber after the frame (when counted)
};

}  // namespace fibscope
