// What a frame is drawn with: the plain settings the command line and the
// viewer's panels edit (STYLE.md rule 10), and the statistics a frame
// reports. No Vulkan here.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fibscope {

// Which pipeline draws the G-buffer (DESIGN.md section 6).
enum class RenderPipeline : uint8_t {
  Compute,     // fiblets: cull -> decode + raster (64-bit atomics) -> resolve
  Lines,       // baseline: raw float vertices as line strips, graphics pipeline, no culling
  RawCompute,  // baseline: the compute raster over raw float vertices, no culling
  // The paper's comparison pipelines (section 4.5, table 2): the same
  // fiblets and cull as Compute, decoded in a geometry shader (one point
  // per fiblet in, a line strip out) or in a tessellation control shader
  // (one-point patches, isolines); graphics line rasterisation.
  Geometry,
  Tessellation,
  // VK_EXT_mesh_shader only (paper 3.3; refused in one line elsewhere): a
  // task shader culls as Compute does, a mesh shader decodes one fiblet per
  // workgroup with the parallel prefix into a line-list meshlet; MeshSerial
  // is the paper's "mesh (1 thread)" comparison (one invocation decodes the
  // fiblet serially). Graphics line rasterisation, as Geometry.
  Mesh,
  MeshSerial,
};

// The pipeline draws the scene's fiblets (scene numbering, the cull), not
// the raw vertices of the baselines.
inline bool drawsFiblets(RenderPipeline pipeline) {
  return pipeline == RenderPipeline::Compute || pipeline == RenderPipeline::Geometry ||
         pipeline == RenderPipeline::Tessellation || pipeline == RenderPipeline::Mesh ||
         pipeline == RenderPipeline::MeshSerial;
}

// The pipeline needs the device's VK_EXT_mesh_shader.
inline bool needsMeshShaders(RenderPipeline pipeline) {
  return pipeline == RenderPipeline::Mesh || pipeline == RenderPipeline::MeshSerial;
}

// Fiblet culling in the fiblet pipelines (drawsFiblets; the baselines never
// cull).
enum class CullingMode : uint8_t {
  None,      // every fiblet is drawn, no LoD
  Frustum,   // dilated frustum (paper eq. 5) and far-view LoD
  TwoPhase,  // Frustum + conservative two-phase occlusion culling
  // Frustum + the paper's coverage buffer (the previous frame's depth
  // re-projected; one pass, NOT conservative: shaders/shared/coverage_push.h)
  Coverage,
};

enum class ColorMode : uint8_t {
  Solid,        // RenderSettings::solid_color
  Orientation,  // |tangent| as RGB (world axes: x red, y green, z blue)
  PerFiber,     // a distinct colour per fiber (hashed from its index)
  // A float per fiber (GpuScene::fiber_scalars, e.g. the fiber lengths)
  // through `colormap` over [scalar_min, scalar_max], clamped. Without
  // scalars (address 0) the frame falls back to Orientation: a viewer that
  // has not loaded them yet still draws.
  Scalar,
  // The view-facing line normal N = normalize(V - (V.T) T) (V towards the
  // eye, T the tangent) in view space as RGB 0.5 + 0.5 N (x right, y up,
  // z towards the viewer): FiberVisualizer's normal colouring for lines. A
  // line seen end-on (T parallel to V) faces the viewer: N = V.
  Normal,
};

// Colormaps of ColorMode::Scalar: 256-entry tables interpolated from a few
// control points (src/render/colormap.h).
enum class Colormap : uint8_t {
  Viridis,    // matplotlib's perceptually uniform default (van der Walt, Smith)
  Magma,      // matplotlib's black -> purple -> orange -> pale yellow
  Grayscale,  // black -> white
  CoolWarm,   // Moreland's diverging blue -> grey -> red (2009)
};

// The voxel axes of an anatomical volume: its slices are the planes
// i = const, j = const, k = const (shared/anatomy.h).
enum class SliceAxis : uint8_t { I, J, K };

// How a slice samples the volume (shared/anatomy.h): trilinear is what
// mrview shows by default; nearest shows the voxels as they are.
enum class SliceSampling : uint8_t { Trilinear, Nearest };

// How spline tubes (src/tubes; Salm) are drawn into the surface target.
enum class TubeMethod : uint8_t {
  Compute,       // ray casting in compute: sub-segment boxes binned into screen tiles (lavapipe, compute-only GPUs)
  Raycast,       // ray casting in the fragment shader over one instanced box per sub-segment (seed 3.2)
  Tessellation,  // adaptively tessellated cylinders (seed 3.1)
};

// Which pass writes the ambient-occlusion factor the shade pass multiplies
// by (when RenderSettings::ssao is on).
enum class AoMethod : uint8_t {
  Ssao,  // screen-space (shaders/ssao.comp)
  // Evans' distance-field AO from the tubes' dense distance field
  // (shaders/df_ao.comp; McGraw's seed, issue 16 item 4): only frames that
  // have one (tubes or the svo pipelines in `render`); elsewhere no AO.
  Df,
};

enum class Lighting : uint8_t {
  None,
  IlluminatedLines,  // Zoeckler / Stalling / Hege: diffuse and specular from the tangent alone
  Pbr,               // FiberVisualizer 10.3: Cook-Torrance (GGX) under a ring of 30 directional lights
};

struct RenderSettings {
  RenderPipeline pipeline = RenderPipeline::Compute;
  CullingMode culling = CullingMode::TwoPhase;
  float lod_pixels = 4.0f;  // far-view LoD below this projected fiblet size (Frustum, TwoPhase, Coverage)
  // Coverage: the splat radius R_S(z) in previous-frame pixels
  // (shared/coverage_push.h; the default, half a pixel's diagonal, gives
  // the unculled frame with the camera still, larger culls more and misses more).
  float coverage_splat_px = 0.70710678f;
  float line_width_px = 1.0f;  // [1, 4]
  ColorMode color = ColorMode::Orientation;
  std::array<float, 3> solid_color = {0.9f, 0.9f, 0.85f};
  // ColorMode::Scalar: the colormap and the scalar range mapped onto it
  // (values outside are clamped; scalar_max >= scalar_min, equal maps every
  // fiber to the middle of the colormap).
  Colormap colormap = Colormap::Viridis;
  float scalar_min = 0.0f;
  float scalar_max = 1.0f;
  // Selection (GpuScene::selection_bits): selected fibers take
  // highlight_color as their base colour (still lit, so they read as
  // lines); unselected ones fade towards the background by dim_unselected
  // in [0, 1] (0: unchanged, 1: invisible). No effect without a selection.
  std::array<float, 3> highlight_color = {1.0f, 0.8f, 0.1f};
  float dim_unselected = 0.7f;
  Lighting lighting = Lighting::IlluminatedLines;
  // Illuminated lines: colour = base * (ambient + diffuse * D) + specular * S^shininess
  // (shaders/shared/shade_push.h).
  float light_ambient = 0.2f;
  float light_diffuse = 0.8f;
  float light_specular = 0.5f;
  float light_shininess = 48.0f;
  // PBR: colour = ambient * albedo + the Cook-Torrance sum over the ring of
  // lights of total radiance pbr_intensity (shaders/shared/shade_push.h).
  // pi makes a white diffuse surface facing the eye come out at
  // cos(45 degrees) of its albedo, about as bright as illuminated lines.
  float pbr_roughness = 0.5f;
  float pbr_metalness = 0.0f;
  float pbr_intensity = 3.14159265f;
  bool ssao = true;
  float ssao_radius_px = 10.0f;
  float ssao_strength = 0.8f;
  // Neighbours nearer than this (view distance, mm) no longer occlude: a
  // bundle far in front of another casts no shadow on it, one lying on it
  // (bundles are about 10 mm thick) does.
  float ssao_range_mm = 10.0f;
  // Multi-scale ambient occlusion (FiberVisualizer section 11.3): 1 is
  // plain SSAO; 2 to 5 also sample at 2, 4, 8, 16 times ssao_radius_px,
  // each scale with half the samples of the one before (ao_samples at the
  // smallest), and the per-scale occlusion factors multiply, so near
  // contacts and whole bundles both darken. The paper's setting: radius 3,
  // 5 scales, 64 samples (3 to 48 px; 64, 32, 16, 8, 4 samples). The
  // default 16 samples keep plain SSAO cheap: the interleaved rotations and
  // the blur make them 256 directions.
  int ao_scales = 1;
  int ao_samples = 16;
  AoMethod ao_method = AoMethod::Ssao;
  // The tubes' distance field (shaders/shared/distance_field.h): its voxel
  // (0: the largest tube radius, coarsened until the field is at most 64
  // MB), read when the field is built (once per tube model). Evans' AO:
  // df_ao_steps samples N at heights 0.5 voxel + i delta along the normal
  // (delta = df_ao_delta_mm, 0: the field's voxel), strength k per delta.
  // Soft shadows from the headlight by sphere tracing the field, penumbra
  // softness k_s (larger: harder edges).
  float df_voxel_mm = 0.0f;
  int df_ao_steps = 5;
  float df_ao_delta_mm = 0.0f;
  float df_ao_strength = 1.0f;
  bool df_shadows = false;
  float df_shadow_softness = 8.0f;
  // FXAA (Lottes' fast approximate anti-aliasing, 3.11 quality-like) over
  // the shaded RGBA8 image: smooths the stair steps of 1-pixel lines.
  bool fxaa = false;
  // Post effects (FiberVisualizer section 12) over the shaded image, after
  // ambient occlusion and before FXAA, in this order; each is off at its
  // default (neutral) value. Formulas: shaders/shared/post_push.h.
  int flatten_levels = 0;     // colour flattening to n levels a channel (2 to 256; 0 or 1: off)
  float contrast = 1.0f;      // (c - 0.5) k + 0.5
  float brightness = 0.0f;    // c + d
  float saturation = 1.0f;    // L + s (c - L), L the Rec. 709 luminance (0: grey)
  float sharpen = 0.0f;       // 3 x 3 sharpening kernel's factor
  std::array<float, 3> background = {0.0f, 0.0f, 0.0f};
  // Cuts (DESIGN.md section 2): fibers are clipped per pixel, not dropped,
  // and a segment crossing a plane is drawn up to the plane
  // (render/clip_planes.h). clip_planes: world (n, d), each keeping
  // n.p + d >= 0; at most shader::kMaxClipPlanes.
  std::vector<std::array<double, 4>> clip_planes;
  // mrview's slab: only what lies within slab_mm / 2 of a plane is drawn
  // (0: no slab). The plane is slab_plane (n, d) when set, e.g. an
  // anatomical slice's, else the focal plane: through the camera's target,
  // facing the viewer, so the slab moves with the view.
  float slab_mm = 0.0f;
  std::optional<std::array<double, 4>> slab_plane;
  // Anatomical slices (GpuScene::anatomy; shared/anatomy.h): the planes of
  // the volume's voxel axes through slice_i, slice_j, slice_k, voxel
  // coordinates (voxel centres at integers; render and the viewer put them
  // at the volume's centre unless given), each drawn when shown. The
  // display range maps anatomy_min to black and anatomy_max to white
  // (render and the viewer set it to the volume's robust range unless
  // given: render/anatomy_slices.h). Opacity 1 hides what is behind a slice;
  // below 1 the fibers behind show through, the slice's grey blended over
  // them by the opacity; 0 draws no slice.
  float slice_i = 0.0f, slice_j = 0.0f, slice_k = 0.0f;
  bool show_slice_i = true, show_slice_j = true, show_slice_k = true;
  float anatomy_min = 0.0f, anatomy_max = 1.0f;
  float anatomy_opacity = 1.0f;
  SliceSampling anatomy_sampling = SliceSampling::Trilinear;
  // The slice the viewer's keys move, and the one the slab follows: with
  // slab_follows_slice and a volume, each frame's slab_plane is that
  // slice's world plane (the frame renderer sets it).
  SliceAxis active_slice = SliceAxis::K;
  bool slab_follows_slice = false;
  // L/R, A/P, S/I at the middle of the image's edges and an axis triad in
  // the bottom-right corner (x red, y green, z blue), stamped over the final
  // image (render/orientation_labels.h). Off here; `render` and `view`
  // turn it on by default.
  bool orientation_labels = false;
  // Spline tubes (when the scene has a tube model): the method, and the
  // tessellation's base mesh (the seed's 16 rings of 8 vertices, refined by
  // the tessellator) and multisampling (1: none; 4, 8: the seed's figures
  // 23-24).
  TubeMethod tube_method = TubeMethod::Compute;
  int tube_rings = 16;
  int tube_vertices = 8;
  int tube_msaa = 1;
};

// The slice position by axis (0 = i, 1 = j, 2 = k).
float slicePosition(const RenderSettings& settings, int axis);
void setSlicePosition(RenderSettings& settings, int axis, float position);

// Parsing and names for the command line ("compute", "two-phase", ...).
// parse* throw Error listing the accepted names.
RenderPipeline parseRenderPipeline(std::string_view name);
CullingMode parseCullingMode(std::string_view name);
ColorMode parseColorMode(std::string_view name);
Lighting parseLighting(std::string_view name);
Colormap parseColormap(std::string_view name);
TubeMethod parseTubeMethod(std::string_view name);
AoMethod parseAoMethod(std::string_view name);
std::string_view renderPipelineName(RenderPipeline pipeline);
std::string_view cullingModeName(CullingMode mode);
std::string_view colorModeName(ColorMode mode);
std::string_view lightingName(Lighting lighting);
std::string_view colormapName(Colormap colormap);
std::string_view tubeMethodName(TubeMethod method);  // "compute", "raycast", "tess"
std::string_view aoMethodName(AoMethod method);      // "ssao", "df"
std::string_view sliceSamplingName(SliceSampling sampling);
std::string_view sliceAxisName(SliceAxis axis);

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
  // Spline tubes' compute ray casting (src/tubes/gpu): screen tiles whose
  // sub-segment list overflowed, each of which tested every sub-segment.
  uint64_t tube_tiles_overflowed = 0;
  // The tube method's own device buffers at this frame's size (tile lists,
  // visibility keys, ...), beside the tubes buffer all methods share.
  uint64_t tube_method_bytes = 0;
};

}  // namespace fibscope
