// Spline tubes by adaptive tessellation (Salm, seed section 3.1; issue 15
// item 2): the patch layout, the refinement constants and the push
// constants of tube_tess.vert / .tesc / .tese / .frag.
//
// Base mesh: every Hermite segment (shared/tubes.h) is a cylinder of
// `rings` rings along u in [0, 1] and `vertices` vertices around, whose
// quads are the patches (one control point each: the patch's index), then
// two rows of `vertices` cap patches: a hemisphere at the segment's start
// and one at its end, drawn only where the segment begins or ends its tube
// (the caps between joined segments are culled in the control stage). So a
// segment is kTubeTessPatchesPerSegment(rings, vertices) patches and patch
// g of the draw is patch g % that of segment g / that:
//   row = (g % per_segment) / vertices, around = g % vertices;
//   row < rings: body quad of ring interval [row, row + 1] / rings;
//   row == rings: the start cap; row == rings + 1: the end cap.
// Hemispherical caps make the tessellated tube the ray caster's
// sphere-swept surface at the ends too (its end spheres), and a one-point
// tube (chord 0) a sphere.
//
// Domain: quads, gl_TessCoord.x around (angle (around + x) / vertices of a
// turn), gl_TessCoord.y along (u = (row + y) / rings; caps: latitude from
// the seam ring, y = 0, to the pole, y = 1). Every edge's level is computed
// from the edge's own two corners in one canonical order, so the two
// patches sharing it give it the same level and the same vertices: no
// cracks, also at the seams between segments and between body and caps.
//
// Two draws of one pipeline (mode below): 1. the nearest fragment per
// pixel by a 64-bit atomicMin of (clip depth bits << 32 | patch index) in
// the stage's visibility buffer, cleared to ~0; 2. the same geometry again,
// and the one fragment whose key is the pixel's writes the surface texel
// when strictly nearer than what other surfaces left. One pipeline for
// both, the pass as a push constant, because the second draw must
// rasterise exactly the first one's depths (the keys are compared for
// equality), which two pipelines do not guarantee.
//
// tube_msaa (samples > 1): the surface target holds one texel per pixel,
// which shading, picking, SSAO and the merge with the lines read, so true
// MSAA (a texel per sample, blended) would change every consumer. What is
// done instead is supersampled coverage: the draws rasterise `samples`
// samples a pixel (one fragment a pixel, depth at the pixel centre); draw
// 1 keeps one key per sample (each covered sample of gl_SampleMaskIn); in
// draw 2 a pixel is the tubes' when at least half its samples are covered
// (by area, not by its centre alone), and the fragment that is nearest at
// the most of its samples writes the texel (ties: the nearer). Edges then follow the
// covered area rather than the pixel centre; the image's antialiasing
// stays FXAA's.
#ifndef FIBSCOPE_SHADERS_SHARED_TUBE_TESS_H
#define FIBSCOPE_SHADERS_SHARED_TUBE_TESS_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define TUBE_TESS_CONST inline constexpr
#else
#define TUBE_TESS_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// Screen-space edge-length criterion: an edge is cut into pieces of about
// kTubeTessEdgePx pixels, at most kTubeTessEdgeClamp pieces. The clamp 5
// bounds what a patch may grow to for its size on screen (a base-mesh
// quad becomes at most 5 x 5 quads: 16 x 8 x 25 = 3,200 quads a segment),
// since the base mesh already follows the curve at 16 rings a segment.
TUBE_TESS_CONST float kTubeTessEdgePx = 8.0f;
TUBE_TESS_CONST float kTubeTessEdgeClamp = 5.0f;
// Silhouette criterion (seed figure 8): a ring edge (around the tube) that
// the silhouette crosses is cut until the faceting error r (1 - cos(pi /
// n)), n = vertices x level facets around, projected (world length / w x
// the viewport's pixels per unit at w = 1) is under kTubeTessSilhouettePx,
// at most kTubeTessSilhouetteClamp pieces. The clamp 7 bounds the
// silhouette refinement: 8 x 7 = 56 facets around leave r (1 - cos(pi /
// 56)) = 0.0016 r, under a quarter pixel for a tube up to 160 px in radius
// on screen; wider tubes take more base vertices (tube-vertices).
TUBE_TESS_CONST float kTubeTessSilhouettePx = 0.25f;
TUBE_TESS_CONST float kTubeTessSilhouetteClamp = 7.0f;
// Back-patch culling: a patch is dropped when at each of its corners the
// surface faces away from the eye by more than this (cosine of the angle
// between the corner's normal and the direction to the eye below
// -kTubeTessBackMargin): a margin for the normals between the corners,
// which a varying radius tilts by atan(dr/ds).
TUBE_TESS_CONST float kTubeTessBackMargin = 0.1f;

TUBE_TESS_CONST uint kTubeTessModeKeys = 0u;    // draw 1: atomicMin of the keys
TUBE_TESS_CONST uint kTubeTessModeTexels = 1u;  // draw 2: the winner writes its texel
TUBE_TESS_CONST uint kTubeTessFlagBackCulling = 1u;
// Frustum culling: a patch is dropped when the sphere around its corners,
// widened by how far the surface between them bulges out (at most the
// faceting and ring-spacing errors, bounded by kTubeTessBulge of the
// sphere's radius plus the tube's), lies outside a frustum plane.
TUBE_TESS_CONST uint kTubeTessFlagFrustumCulling = 2u;
TUBE_TESS_CONST float kTubeTessBulge = 0.25f;

SHADER_FN uint tubeTessPatchesPerSegment(uint rings, uint vertices) { return (rings + 2u) * vertices; }

struct TubeTessPush {
  uint64_t camera;      // CameraBlock
  uint64_t nodes;       // TubeNode[]
  uint64_t segments;    // TubeSegment[]
  uint64_t visibility;  // uint64_t per pixel, row-major
  uint64_t surface;     // SurfaceTexel per pixel (draw 2 reads and writes it)
  uint width;           // frame width (pixels), the row length of both
  uint rings;           // base mesh rings a segment (>= 1)
  uint vertices;        // base mesh vertices around (>= 3)
  uint segment_count;   // segments in the tubes buffer (joins are looked up)
  uint mode;            // kTubeTessMode*
  uint flags;           // kTubeTessFlag*
  uint samples;         // rasterisation samples (tube_msaa): keys per pixel
  uint pad0;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::TubeTessPush) == 72, "");
static_assert(offsetof(fibscope::shader::TubeTessPush, width) == 40, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_TUBE_TESS_H
