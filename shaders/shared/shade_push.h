// Push constants of the shading passes (DESIGN.md section 6, "Shading"):
// G-buffer (shared/gbuffer.h) + camera block -> RGBA8, optionally through
// screen-space ambient occlusion. One struct per pass; the pass's shader file
// names it. Buffers are device addresses; the uint64_t members come first
// and the rest are 4-byte scalars, so std430 and C++ agree.
//
//   tile_classify.comp  G-buffer -> the list of 8 x 8 tiles with a covered pixel
//   ssao.comp       G-buffer depth -> raw ambient-occlusion factor per pixel
//   ssao_blur.comp  depth-aware separable blur of that factor (run twice: x, y)
//   shade.comp      colour x lighting x ambient occlusion -> RGBA8
//   fxaa.comp       optional anti-aliasing of that RGBA8 image
#ifndef FIBSCOPE_SHADERS_SHARED_SHADE_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_SHADE_PUSH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define SHADE_CONST inline constexpr
#else
#define SHADE_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// The colour mode (RenderSettings::color): shade.comp's kShadeSpecColorMode.
SHADE_CONST uint kShadeColorSolid = 0u;
SHADE_CONST uint kShadeColorOrientation = 1u;
SHADE_CONST uint kShadeColorPerFiber = 2u;
SHADE_CONST uint kShadeColorScalar = 3u;
SHADE_CONST uint kShadeColorNormal = 4u;
// Entries of one colormap table (src/render/colormap.h).
SHADE_CONST uint kShadeColormapEntries = 256u;
// ColorMode::Normal: below this |V - (V.T) T| the line is seen end-on and
// N = V (the tangent's 16-bit octahedral encoding is good to ~1e-4).
SHADE_CONST float kShadeNormalParallelEps = 1e-3f;
// The lighting (RenderSettings::lighting): shade.comp's kShadeSpecLighting.
SHADE_CONST uint kShadeLightingNone = 0u;
SHADE_CONST uint kShadeLightingIlluminated = 1u;
SHADE_CONST uint kShadeLightingPbr = 2u;

// Physically based lighting (FiberVisualizer section 10.3): a fixed set of
// kPbrLights directional lights of equal radiance, a ring around the view
// axis (light i at polar angle kPbrRingPolar from the direction towards the
// eye, azimuth 2 pi i / kPbrLights from the camera's right axis), in view
// space like the headlight, so the model is lit alike from whichever side
// it is seen: a ring light, every surface facing the eye lit from all
// round, silhouettes from one side only. The paper places its 30 lights
// around the model; the polar angle is ours (45 degrees: the highlights of
// a tube sit between its axis and its rim).
SHADE_CONST uint kPbrLights = 30u;
SHADE_CONST float kPbrRingPolar = 0.78539816f;  // pi / 4
// Cook-Torrance's denominator 4 (N.L)(N.V) is kept above this, so grazing
// pixels do not divide by zero.
SHADE_CONST float kPbrMinDenominator = 1e-4f;

// Neighbours sampled per pixel by ssao.comp (a Vogel spiral, turned by one
// of kSsaoRotations angles chosen by the pixel's place in a 4 x 4 tile:
// interleaved sampling, Keller & Heidrich 2001), and the blur's half width
// in pixels: 2, with weights 1 2 2 2 1, gives each of the 4 phases of the
// tile the same weight along a row and along a column, so on a region of
// one depth the two blur passes average the 16 rotations exactly.
// The smallest scale takes RenderSettings::ao_samples neighbours (at most
// kSsaoMaxSamples), each larger scale half as many as the one before, never
// fewer than kSsaoMinSamples (FiberVisualizer section 11.3: 64 at the
// smallest scale, halved at each larger one).
SHADE_CONST uint kSsaoMaxSamples = 64u;
SHADE_CONST uint kSsaoMinSamples = 4u;
SHADE_CONST uint kSsaoRotations = 16u;
SHADE_CONST uint kSsaoBlurRadius = 2u;
// RenderSettings::ao_scales at most: radii r, 2r, 4r, 8r, 16r (the paper's
// 3 to 50 px over up to 5 scales is r = 3: 3, 6, 12, 24, 48).
SHADE_CONST uint kSsaoMaxScales = 5u;
// Neighbours nearer than this (mm) do not occlude (SsaoPush::epsilon_mm):
// fibers side by side in a bundle are at most a few tenths of a millimetre
// apart in depth across a few pixels.
SHADE_CONST float kSsaoEpsilonMm = 0.3f;
// The blur mixes pixels within this distance in depth
// (SsaoBlurPush::depth_tolerance_mm): the same layer of a bundle, not an
// occluder with the fiber it darkens.
SHADE_CONST float kSsaoBlurDepthToleranceMm = 1.0f;

// The headlight: the direction towards the light in VIEW space (x right,
// y up, +z towards the viewer), a little above and to the left of the eye so
// that lines facing the viewer are not all equally lit. Not normalised here
// (shared code does no sqrt); the shaders and the tests normalise it.
SHADE_CONST float kShadeLightViewX = -0.35f;
SHADE_CONST float kShadeLightViewY = 0.45f;
SHADE_CONST float kShadeLightViewZ = 1.0f;

// tile_classify.comp: one invocation per pixel; the first subgroup to find
// a covered pixel in a kPixelGroupSize x kPixelGroupSize tile sets the
// tile's flag (flags: uint per tile, zeroed before) and appends the tile's
// index (ty * tiles_x + tx) to `tiles` (shared/fiblet_list.h layout, count
// zeroed before). ssao, ssao_blur and shade then run one workgroup per
// listed tile (dispatched indirectly, the list finalised as the fiblet
// lists are): empty tiles cost nothing there (their colour is the
// background, filled before), which on a CPU device, whose SIMD lanes run
// every branch, is most of a frame's pixels.
struct TileClassifyPush {
  uint64_t gbuffer;
  uint64_t flags;
  uint64_t tiles;
  uint width;
  uint height;
};

// ssao.comp: per covered pixel, the fraction of `samples` neighbours
// within radius_px that lie nearer the camera than the pixel by more than
// epsilon_mm and less than range_mm (a smooth falloff ends at range_mm),
// weighted by closeness; ao = 1 - strength * fraction. Empty pixels get 1.
// Multi-scale (scales > 1): the same at radius_px * 2^k for k = 0 ..
// scales - 1 with max(samples >> k, kSsaoMinSamples) neighbours (each
// scale's spiral turned by a further golden angle), and ao = the product of
// the per-scale factors, so more scales never lighten.
// Anatomical slices (fiber kNoFiberObject) take none (1) and cast none.
struct SsaoPush {
  uint64_t camera;   // CameraBlock: depth_range linearises the clip depth
  uint64_t gbuffer;  // GBufferTexel per pixel
  uint64_t ao;       // float per pixel (written)
  uint64_t tiles;    // the covered tiles (tile_classify.comp): one workgroup each
  uint width;
  uint height;
  float radius_px;
  float epsilon_mm;
  float range_mm;
  float strength;
  uint scales;   // 1 .. kSsaoMaxScales
  uint samples;  // the smallest scale's, kSsaoMinSamples .. kSsaoMaxSamples
};

// ssao_blur.comp: ao_out = the average of ao_in over the 2 * kSsaoBlurRadius
// + 1 pixels along (step_x, step_y), weighted 1 2 2 2 1 and counting only
// covered pixels whose view depth is within depth_tolerance_mm of the
// centre's. Empty pixels copy their value.
struct SsaoBlurPush {
  uint64_t camera;
  uint64_t gbuffer;
  uint64_t ao_in;   // float per pixel
  uint64_t ao_out;  // float per pixel (written)
  uint64_t tiles;   // the covered tiles: one workgroup each
  uint width;
  uint height;
  int step_x;  // (1, 0): horizontal pass, (0, 1): vertical pass
  int step_y;
  float depth_tolerance_mm;
  uint pad0;
};

// shade.comp: per pixel, base colour (the colour mode) times lighting,
// times the ambient-occlusion factor when ao != 0, packed as RGBA8 (R in
// the low byte, A = 255), in the covered tiles (one workgroup each; the
// others hold the background already); empty pixels get the background
// colour. The colour mode, the lighting and whether the frame has surfaces
// are specialisation constants (kShadeSpec*), one pipeline per combination,
// so no pixel pays for the branches of the others; the parameters are in a
// ShadeBlock that the pass writes into its own buffer each frame.
// Illuminated lines (Zoeckler, Stalling, Hege 1996) with T the tangent, L
// the light and V the direction towards the eye:
//   diffuse  = sqrt(1 - (L.T)^2)
//   specular = max(0, sqrt(1 - (L.T)^2) sqrt(1 - (V.T)^2) - (L.T)(V.T))^shininess
//   colour   = base * (ambient + diffuse_k * diffuse) + specular_k * specular
// Surface pixels (GBufferTexel::segment has kGBufferSurface; their normal N
// and colour come from the surface target, N turned towards the eye) take
// Blinn-Phong with the same light and coefficients instead:
//   diffuse  = max(0, N.L), specular = max(0, N.H)^shininess, H = normalize(L + V)
// and their own colour where its alpha is > 0, else the colour mode's
// (Normal: N itself). Anatomical slices (kSurfaceSourceSlice) are not lit
// and take no occlusion: their grey is the window/level's, blended over
// the background by their alpha (1 for an opaque slice). With translucent
// slices (kShadeSpecTranslucentSlices), a pixel whose surface texel is a
// slice nearer than its G-buffer texel (which the merge kept) ends as
// mix(its colour, the slice's grey, the slice's alpha).
// PBR (kShadeLightingPbr; Cook-Torrance, Karis 2013's real-time terms) with
// N the surface normal or, for lines, the view-facing normal in the plane
// of T and V (N = normalize(V - (V.T) T); V when the line is seen end-on),
// albedo the base colour, rho = roughness, m = metalness, for each of the
// kPbrLights directions L with H = normalize(L + V):
//   D = a^2 / (pi ((N.H)^2 (a^2 - 1) + 1)^2),  a = rho^2          (GGX)
//   G = G1(N.V) G1(N.L), G1(x) = x / (x (1 - k) + k), k = (rho + 1)^2 / 8
//                                                  (Schlick-GGX, Smith)
//   F = F0 + (1 - F0) (1 - H.V)^5, F0 = mix(0.04, albedo, m)  (Schlick)
//   colour += (kd albedo / pi + D G F / max(4 (N.L)(N.V), kPbrMinDenominator))
//             * (light_intensity / kPbrLights) * N.L          for N.L > 0,
//   kd = (1 - F)(1 - m); and colour starts at ambient * albedo.
// Base colours: Scalar reads fiber_scalars[fiber] and the colormap table
// (entry round(255 t), t = (s - scalar_min) / (scalar_max - scalar_min)
// clamped, NaN -> 0, max == min -> 0.5); a fiber id >= fiber_count falls
// back to Orientation (the frame without scalars uses the Orientation
// pipeline). Normal: 0.5 + 0.5 N in view space, N = normalize(V - (V.T) T),
// or V when that is shorter than kShadeNormalParallelEps. Selection
// (selection_bits != 0): selected fibers take the highlight colour as base;
// unselected ones end as mix(colour, background, dim_unselected) after
// lighting and occlusion.
// Soft shadows (shadow != 0, df_shadow.comp's factor s per pixel): the
// direct light (diffuse and specular, or PBR's sum over the ring) scales
// by s, the ambient term not:
//   colour = base * ambient + s * (lit colour - base * ambient)
// (no lighting: no shadows); frames without shadows run the formulas
// above unchanged.
SHADE_CONST uint kShadeSpecColorMode = 0u;  // constant_id: kShadeColor*
SHADE_CONST uint kShadeSpecLighting = 1u;   // constant_id: kShadeLighting*
SHADE_CONST uint kShadeSpecSurfaces = 2u;   // constant_id: 1 when the frame has surfaces
SHADE_CONST uint kShadeSpecTranslucentSlices = 3u;  // constant_id: 1 when its slices are translucent
struct ShadePush {
  uint64_t camera;
  uint64_t gbuffer;
  uint64_t surface;  // SurfaceTexel per pixel (surface pipelines only), or 0
  uint64_t ao;       // float per pixel, or 0: no ambient occlusion
  uint64_t color;    // uint per pixel (written)
  uint64_t tiles;    // the covered tiles (tile_classify.comp): one workgroup each
  uint64_t block;    // ShadeBlock
  uint64_t shadow;   // float per pixel (df_shadow.comp), or 0: no shadows
  uint width;
  uint height;
};

// The shading parameters of one frame (written by the shade pass with the
// frame's commands).
struct ShadeBlock {
  uint64_t fiber_scalars;   // float per fiber, or 0
  uint64_t selection_bits;  // uint words, bit f % 32 of word f / 32; or 0: no selection
  uint solid;       // RGBA8: the solid base colour (8 bits a channel, as the image)
  uint background;  // RGBA8 (what the image stores anyway)
  float ambient;
  float diffuse;
  float specular;
  float shininess;
  float scalar_min;
  float scalar_max;
  uint highlight;  // RGBA8
  float dim_unselected;
  uint fiber_count;  // fibers the scalars and selection bits cover
  float roughness;   // PBR, in [0.05, 1] (the settings table's range: 0 would make D a spike)
  float metalness;   // PBR, in [0, 1]
  float light_intensity;  // PBR: the ring's total radiance (each light's is 1 / kPbrLights of it)
  uint pad0;
  uint pad1;
  uint colormap[kShadeColormapEntries];  // RGBA8: the chosen colormap's table
};

// fxaa.comp: FXAA in the manner of Lottes' FXAA 3.11 "quality" preset, on
// RGBA8 in -> RGBA8 out (A = 255). Per pixel, with luma = 0.299 R + 0.587 G
// + 0.114 B of the stored (sRGB) values:
//   1. the local contrast of the pixel and its 4 neighbours; below
//      max(edge_threshold_min, edge_threshold * max luma) the pixel is copied;
//   2. the edge is horizontal or vertical by which second differences of
//      the 3x3 neighbourhood are larger; its far side is the neighbour across
//      it with the steeper gradient;
//   3. the edge is followed both ways (kFxaaSearchSteps steps of growing
//      length) on the luma averaged across it until it departs from the
//      local average by a quarter of the gradient: the ends;
//   4. a pixel nearer the end where the edge turns its way blends towards
//      the far side by 0.5 - (distance to the nearer end) / (edge length);
//   5. sub-pixel aliasing (a lone bright pixel) blends by subpix * s^2, s
//      a smoothstep of |3x3 weighted average luma - luma| / contrast;
// and the output is mix(pixel, far-side neighbour, the larger blend).
SHADE_CONST uint kFxaaSearchSteps = 12u;
struct FxaaPush {
  uint64_t color_in;   // uint per pixel
  uint64_t color_out;  // uint per pixel (written)
  uint width;
  uint height;
  float edge_threshold;
  float edge_threshold_min;
  float subpix;
  uint pad0;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::TileClassifyPush) == 32, "");
static_assert(sizeof(fibscope::shader::SsaoPush) == 64, "");
static_assert(sizeof(fibscope::shader::SsaoBlurPush) == 64, "");
static_assert(sizeof(fibscope::shader::ShadePush) == 72, "");
static_assert(offsetof(fibscope::shader::ShadePush, width) == 64, "scalars follow the eight addresses");
static_assert(offsetof(fibscope::shader::ShadeBlock, solid) == 16, "");
static_assert(offsetof(fibscope::shader::ShadeBlock, roughness) == 60, "");
static_assert(offsetof(fibscope::shader::ShadeBlock, colormap) == 80, "");
static_assert(sizeof(fibscope::shader::ShadeBlock) == 80 + 4 * fibscope::shader::kShadeColormapEntries, "");
static_assert(sizeof(fibscope::shader::FxaaPush) == 40, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_SHADE_PUSH_H
