// The coverage buffer of CullingMode::Coverage (the fiblets paper's
// occlusion culling, section 3.4 and appendix C; DESIGN.md section 6):
// coverage_reproject.comp's push constants and the splat radius.
//
// One pass a frame, one frame of latency: at the end of frame N its
// visibility keys and camera are kept (CoverageHistory,
// render/gpu/coverage_pass.h); at frame N+1, before the cull, every covered
// pixel of N becomes a world point (unprojected with N's inverse
// view-projection at the pixel centre and its depth) and is splatted into
// the new frame: its occluder is a hemisphere of world radius R_S(z)
// around the point, carved towards the viewer (the half facing the new
// eye is removed: only what lies behind the fiber's surface is claimed to
// be covered). Its screen footprint is a disc of the projected radius
// R_S * focal / w; the depth written is the depth of the hemisphere's back,
// the point pushed R_S further along the new view ray (the farthest depth
// of the surface it covers, so a fiblet must lie behind all of it to be
// culled). Per pixel the nearest such depth wins (atomicMin on the float
// bits: non-negative floats order like their bits); pixels no splat
// reaches keep 1.0, the far plane: nothing occludes there. The cull then
// tests each fiblet's sphere against the max-mip pyramid of this buffer
// exactly as two-phase's phase 2 tests it against the pyramid of phase 1
// (fiblet_cull.comp, sphereOccluded), and draws only what passes: no
// second phase, so a fiblet hidden in frame N and uncovered in N+1 is
// missed. That is the method's artifact (the paper's figure 9), which
// tests/unit/gpu_coverage_test.cpp and `fibscope bench --count-missed`
// count.
//
// R_S(z) (paper eq. 4): its exact form was not available when this was
// written, so it is derived from the property the paper asks of it: a
// splat covers at least the pixel footprint of the sample it comes from.
// A previous-frame pixel at view depth z spans z / focal_prev world mm
// (focal_prev = |P[1][1]| * height / 2 of frame N), and a disc covering its
// square needs the half diagonal, so
//     R_S(z) = kCoverageSplatPixels * z / focal_prev,  kCoverageSplatPixels = sqrt(2) / 2.
// Why not more: with the camera still, a splat then reaches only its own
// pixel centre (the neighbours' centres are 1 px away), so the coverage of
// a pixel is its own fiber pushed back by R_S, every fiblet visible in N
// passes the test, and the frame equals the unculled one (tested). A
// larger radius would spread near fibers' depths over the gaps beside
// them and cull the fibers seen through those gaps even with the camera
// still. The price, measured (docs/BENCHMARKS.md): once the camera moves,
// the parallax between fibers at different depths opens gaps that no
// sample of frame N covers, the max over a fiblet's rectangle meets one,
// and little is culled (99 % of the fiblets drawn at 1.14 degree steps,
// against two-phase's 93 %). A radius of several pixels would fill those
// gaps, cull more and miss more (the paper's figure 9): the setting
// "coverage-splat" chooses k. Splats are capped at kCoverageMaxSplatPixels (a sample very close
// to the new eye would otherwise cover a large disc: fewer pixels covered
// only means less culling, never an error).
#ifndef FIBSCOPE_SHADERS_SHARED_COVERAGE_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_COVERAGE_PUSH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cstddef>
#endif

#ifdef __cplusplus
#define COVERAGE_CONST inline constexpr
#else
#define COVERAGE_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// The default of RenderSettings::coverage_splat_px (the setting
// "coverage-splat" chooses another k).
COVERAGE_CONST float kCoverageSplatPixels = 0.70710678f;  // sqrt(2) / 2: half a pixel's diagonal
COVERAGE_CONST float kCoverageMaxSplatPixels = 4.0f;      // disc radius cap in new-frame pixels
// floatBitsToUint(1.0): the cleared coverage (far plane, nothing occludes).
COVERAGE_CONST uint kCoverageFarBits = 0x3F800000u;

// coverage_reproject.comp: one invocation per pixel of the previous frame.
struct CoverageReprojectPush {
  // First: std430 aligns a vec4 to 16 bytes, the C++ mirror does not.
  vec4 previous_inverse_view_projection[4];  // frame N's clip -> world, columns
  uint64_t previous;  // frame N's visibility keys (its layout: visibilityIndex)
  uint64_t coverage;  // uint per pixel of the new frame, row-major: the pyramid's level 0 as float bits
  uint64_t camera;    // the new frame's CameraBlock
  uint width;         // px, both frames (a size change drops the history)
  uint height;
  float previous_focal_px;  // |P[1][1]| * height / 2 of frame N
  float focal_px;           // the same for the new frame
  float splat_pixels;       // k of R_S(z) (RenderSettings::coverage_splat_px)
  uint pad;                 // to a multiple of 16 bytes, as std430 sizes the struct
};

// R_S(z): the world radius of the hemisphere around a sample at view depth
// `view_depth_mm` of frame N, `splat_pixels` (k) of its pixels (see above).
SHADER_FN float coverageSplatRadius(float view_depth_mm, float previous_focal_px, float splat_pixels) {
  return splat_pixels * view_depth_mm / previous_focal_px;
}

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::CoverageReprojectPush) == 112, "");
static_assert(offsetof(fibscope::shader::CoverageReprojectPush, previous) == 64, "");
static_assert(offsetof(fibscope::shader::CoverageReprojectPush, width) == 88, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_COVERAGE_PUSH_H
