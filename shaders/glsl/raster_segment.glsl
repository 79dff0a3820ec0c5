// The pixel rule of the CPU reference rasteriser (src/render/
// reference_raster.h, steps 1-7) for one world-space segment, writing
// 64-bit visibility keys with atomicMin. Shared by the fiblet raster and the
// raw-compute raster so both follow the same contract.
//
// The reference visits every pixel of the capsule's bounding box; here one
// invocation walks the capsule along its major axis and tests, per column
// (or row), only the pixels of a conservative span around the segment, so a
// long diagonal segment costs its length times the line width, not its
// bounding box. The per-pixel test is the reference's, in float.
#ifndef FIBSCOPE_GLSL_RASTER_SEGMENT_GLSL
#define FIBSCOPE_GLSL_RASTER_SEGMENT_GLSL

#include "shared/render_config.h"
#include "glsl/render_buffers.glsl"
#include "glsl/cut_mesh.glsl"

const float kSpanMargin = 1.0 / 64.0;

// Step 2: both ends outside the same frustum plane.
bool segmentOutsideFrustum(vec4 a, vec4 b) {
  return (a.x < -a.w && b.x < -b.w) || (a.x > a.w && b.x > b.w) || (a.y < -a.w && b.y < -b.w) ||
         (a.y > a.w && b.y > b.w) || (a.z < 0.0 && b.z < 0.0) || (a.z > a.w && b.z > b.w);
}

// Whether the centre of pixel (px, py) lies within `radius` of the segment
// (step 5): rasterPixel's test alone.
bool pixelCovered(int px, int py, vec3 a, vec3 ab, float length2, float radius2) {
  const vec2 c = vec2(float(px) + 0.5, float(py) + 0.5);
  float t = 0.0;
  if (length2 > 0.0) t = clamp(dot(c - a.xy, ab.xy) / length2, 0.0, 1.0);
  const vec2 e = c - (a.xy + t * ab.xy);
  return dot(e, e) <= radius2;
}

// Covers pixel (px, py) with the segment a -> b (window x, y and depth)
// when its centre lies within `radius` of it (step 5), nearest key wins
// (steps 6, 7).
void rasterPixel(VisibilityRef vis, uint width, int px, int py, vec3 a, vec3 ab, float length2, float radius2,
                 uint64_t payload, CutMeshFrame cuts, uint pixels) {
  const vec2 c = vec2(float(px) + 0.5, float(py) + 0.5);
  float t = 0.0;
  if (length2 > 0.0) t = clamp(dot(c - a.xy, ab.xy) / length2, 0.0, 1.0);
  const vec2 e = c - (a.xy + t * ab.xy);
  if (dot(e, e) > radius2) return;
  float depth = a.z + t * ab.z;
  if (depth > 1.0) return;  // beyond the far plane
  if (!(depth > 0.0)) depth = 0.0;  // also maps -0.0, whose bits would sort last
  // A plain load first: where the pixel already holds a nearer key (most
  // fragments of a dense tractogram) the atomic is skipped. Keys only
  // decrease, so a stale load can only let an atomic through, never skip a
  // needed one.
  const uint index = visibilityIndex(uint(px), uint(py), width);
  // A mesh cut discards the fragment (the pixel's own depth range, exact).
  if (cuts.mesh_count != 0u && !cutMeshesKeep(cuts, pixels, uint(py) * width + uint(px), depth)) return;
  const uint64_t key = visibilityKey(depth, payload);
  if (key < vis.keys[index]) atomicMin(vis.keys[index], key);
}

// Steps 2-7 for a segment whose ends are already in clip space (step 1):
// a polyline projects each point once and passes consecutive pairs.
void rasterClipSegment(VisibilityRef vis, CameraBlock cam, vec4 c0, vec4 c1, uint64_t payload) {
  if (segmentOutsideFrustum(c0, c1)) return;
  // Step 2b: the cuts' clip planes (CameraBlock::clip_space), each keeping
  // n.c >= 0: a segment wholly outside one is dropped, one crossing it is
  // cut where it crosses (the drawn part ends on the plane).
  const uint planes = uint(cam.cuts.x);
  for (uint i = 0u; i < planes; ++i) {
    const vec4 plane = cam.clip_space[i];
    const float d0 = dot(plane, c0), d1 = dot(plane, c1);
    if (d0 < 0.0 && d1 < 0.0) return;
    if (d0 < 0.0 || d1 < 0.0) {
      const vec4 cut = c0 + (d0 / (d0 - d1)) * (c1 - c0);
      if (d0 < 0.0) c0 = cut; else c1 = cut;
    }
  }
  // Step 3: cut at the near plane z_clip = 0.
  if (c0.z < 0.0 || c1.z < 0.0) {
    const float t = c0.z / (c0.z - c1.z);
    vec4 cut = c0 + t * (c1 - c0);
    cut.z = 0.0;
    if (c0.z < 0.0) c0 = cut; else c1 = cut;
  }
  const uint width = uint(cam.viewport.x), height = uint(cam.viewport.y);
  const vec2 half_size = 0.5 * cam.viewport.xy;
  const vec3 a = vec3((c0.xy / c0.w + 1.0) * half_size, c0.z / c0.w);
  const vec3 b = vec3((c1.xy / c1.w + 1.0) * half_size, c1.z / c1.w);
  if (any(isnan(a)) || any(isnan(b)) || any(isinf(a)) || any(isinf(b))) return;
  const float radius = 0.5 * cam.viewport.z;
  const vec3 ab = b - a;
  const float length2 = dot(ab.xy, ab.xy);
  const float radius2 = radius * radius;
  // A short segment (the common case at whole-brain zoom: steps of a pixel
  // or less) has all its candidate centres (those within `radius` of its
  // box) in one 2 x 2 block: tested straight, without the walk's nested
  // loops, whose trip counts differ from lane to lane (on a CPU device the
  // SIMD lanes run the longest lane's loop: 2.4x the pixel tests needed).
  // The block's other pixels fail the per-pixel test, so the result is the
  // walk's.
  if (max(abs(ab.x), abs(ab.y)) + 2.0 * radius < 2.0) {
    const int x0 = int(ceil(min(a.x, b.x) - radius - 0.5)), y0 = int(ceil(min(a.y, b.y) - radius - 0.5));
    // First which of the four pass the per-pixel distance test (arithmetic
    // only), then one memory access per covered pixel, in a loop whose trip
    // count is the lane's number of covered pixels (one or two for a line
    // of width 1): on a CPU device every memory access of the program costs
    // its per-lane loop whether or not a lane takes it, and four unrolled
    // tests cost four.
    uint covered = 0u;
    for (int j = 0; j < 4; ++j) {
      const int px = x0 + (j & 1), py = y0 + (j >> 1);
      if (px >= 0 && py >= 0 && px < int(width) && py < int(height) &&
          pixelCovered(px, py, a, ab, length2, radius2))
        covered |= 1u << j;
    }
    while (covered != 0u) {
      const int j = findLSB(covered);
      covered &= covered - 1u;
      rasterPixel(vis, width, x0 + (j & 1), y0 + (j >> 1), a, ab, length2, radius2, payload, cam.mesh_cuts,
                  width * height);
    }
    return;
  }
  // Walk the major axis; `major` / `minor` index x or y.
  const bool x_major = abs(ab.x) >= abs(ab.y);
  const int major = x_major ? 0 : 1, minor = 1 - major;
  const float extent_major = x_major ? float(width) : float(height);
  const float extent_minor = x_major ? float(height) : float(width);
  // Candidate centres m + 0.5 in [min - r, max + r] (as the reference),
  // clamped in float before converting: ends near the near plane can be far
  // off screen.
  const float lo = max(ceil(min(a[major], b[major]) - radius - 0.5), 0.0);
  const float hi = min(floor(max(a[major], b[major]) + radius - 0.5), extent_major - 1.0);
  const float slope = ab[major] != 0.0 ? ab[minor] / ab[major] : 0.0;  // |slope| <= 1
  const float minor_lo_seg = min(a[minor], b[minor]), minor_hi_seg = max(a[minor], b[minor]);
  for (float m = lo; m <= hi; m += 1.0) {
    // The segment's minor coordinate over the major range [centre - r,
    // centre + r], clamped to the segment, widened by r: every pixel centre
    // of this column within r of the segment lies in it.
    const float cm = m + 0.5;
    const float s0 = a[minor] + slope * (cm - radius - a[major]);
    const float s1 = a[minor] + slope * (cm + radius - a[major]);
    const float span_lo = max(min(s0, s1), minor_lo_seg) - radius;
    const float span_hi = min(max(s0, s1), minor_hi_seg) + radius;
    // A margin of 1/64 px for float rounding in the span (the per-pixel
    // test is exact).
    const float n_lo = max(ceil(span_lo - 0.5 - kSpanMargin), 0.0);
    const float n_hi = min(floor(span_hi - 0.5 + kSpanMargin), extent_minor - 1.0);
    for (float n = n_lo; n <= n_hi; n += 1.0) {
      const int px = x_major ? int(m) : int(n);
      const int py = x_major ? int(n) : int(m);
      rasterPixel(vis, width, px, py, a, ab, length2, radius2, payload, cam.mesh_cuts, width * height);
    }
  }
}

// Steps 1-7 for the world-space segment p0 -> p1.
void rasterSegment(VisibilityRef vis, CameraBlock cam, vec3 p0, vec3 p1, uint64_t payload) {
  rasterClipSegment(vis, cam, cameraTransformPoint(cam.view_projection, p0), cameraTransformPoint(cam.view_projection, p1),
                    payload);
}

#endif
