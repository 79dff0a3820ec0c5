// CPU reference rasteriser of raw polylines, for tests only.
//
// It draws every segment of a Tractogram with a Camera (src/render/camera.h)
// into a frame of per-pixel nearest depth, fiber, point and tangent. The GPU
// pipelines are compared against it with the pixel metrics of
// src/render/image_compare.h, so the pixel rule below is the contract the
// GPU rasterisers follow:
//
//   1. Both ends of segment (p_i, p_i+1) go to clip space with
//      viewProjection(camera) (computed in double here).
//   2. A segment whose ends both lie outside the same frustum plane
//      (x < -w, x > w, y < -w, y > w, z < 0 or z > w for both) is skipped.
//   3. The segment is clipped against the near plane z_clip >= 0 in clip
//      space (linear interpolation of the clip coordinates); then w > 0.
//   4. Its ends go to window coordinates: x_w = (x/w + 1) * W / 2,
//      y_w = (y/w + 1) * H / 2 (y down), depth d = z/w.
//   5. Pixel (px, py) is covered when its centre c = (px + 0.5, py + 0.5)
//      lies within distance line_width / 2 of the 2D segment (a capsule,
//      round caps; "within" includes equality). Let t in [0, 1] be the
//      parameter of the point of the 2D segment closest to c (t = 0 for a
//      segment that projects to a point); the fragment's depth is
//      d0 + t * (d1 - d0) (z/w is affine in window coordinates along a
//      projected line, so this is the depth of the 3D line at that point).
//   6. A fragment with depth > 1 (beyond the far plane) is dropped.
//   7. The nearest depth wins; equal depths are resolved by the smaller
//      (fiber, point) pair, so the frame does not depend on drawing order.
//
// Each pixel that wins keeps the fiber (streamline index), the point index
// of the segment's first point WITHIN its fiber, and the segment's
// world-space unit tangent (p_i+1 - p_i normalised; zero for a zero-length
// segment). Streamlines of fewer than two points draw nothing.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/tractogram.h"
#include "io/obj_mesh.h"
#include "render/camera.h"

namespace fibscope {

inline constexpr float kEmptyDepth = std::numeric_limits<float>::infinity();
inline constexpr uint32_t kNoFiber = 0xFFFFFFFFu;
inline constexpr float kMinLineWidth = 1.0f;
inline constexpr float kMaxLineWidth = 4.0f;

// A mesh cut's per-pixel depth range (shared/cut_mesh.h's rule), from the
// eye ray through each pixel centre against the mesh's triangles
// (select/cut_mesh.h rayMeshHits, in float): the nearest entering hit and
// the nearest leaving one with clip depth in [0, 1] (kEmptyDepth where
// none). Fragments inside the range are dropped (cull_inside) or those
// outside it.
struct ReferenceMeshCut {
  std::vector<float> front, back;
  bool cull_inside = true;
};

struct ReferenceFrame {
  uint32_t width = 0, height = 0;
  // Mesh cuts applied to every fragment written (set before drawing).
  std::vector<ReferenceMeshCut> mesh_cuts;
  // Row-major, index = py * width + px, py = 0 the top row.
  std::vector<float> depth;          // clip z/w in [0, 1]; kEmptyDepth where nothing is drawn
  std::vector<uint32_t> fiber;       // kNoFiber where nothing is drawn
  std::vector<uint32_t> point;       // first point of the winning segment, within its fiber
  std::vector<std::array<float, 3>> tangent;  // world-space unit tangent; 0 where nothing is drawn
  std::vector<uint32_t> fragments;   // how many segments covered the pixel (overdraw)

  ReferenceFrame() = default;
  ReferenceFrame(uint32_t w, uint32_t h);
  size_t index(uint32_t px, uint32_t py) const { return size_t(py) * width + px; }
  bool covered(uint32_t px, uint32_t py) const { return fiber[index(px, py)] != kNoFiber; }
  size_t coveredPixels() const;
  // 1 where a segment was drawn, else 0 (the input of compareCoverage).
  std::vector<uint8_t> coverageMask() const;
};

// One end of a segment in window coordinates (after steps 1-4).
struct WindowVertex {
  double x = 0, y = 0;  // px, y down
  double depth = 0;     // clip z/w
};

// Step 5-7 for one segment already in window coordinates: writes its
// fragments into `frame`. Exposed so tests (and GPU comparisons) can check
// the pixel rule without a camera. Only the pixels of the capsule's bounding
// box are visited.
void rasterizeWindowSegment(ReferenceFrame& frame, const WindowVertex& a, const WindowVertex& b,
                            uint32_t fiber, uint32_t point, const std::array<float, 3>& tangent,
                            float line_width_px);

// Draws every segment of `tractogram` (steps 1-7). Throws Error for an
// invalid camera, a line width outside [kMinLineWidth, kMaxLineWidth], or
// more than 2^32 - 1 streamlines or points per streamline.
// With `clip_planes` (world (n, d), each keeping n.p + d >= 0), each
// segment is first cut to the kept side of every plane in world space
// (step 2b: the part left is drawn, its clipped ends on the planes; the
// tangent stays the whole segment's).
ReferenceFrame rasterizeReference(const Tractogram& tractogram, const Camera& camera,
                                  float line_width_px = 1.0f,
                                  const std::vector<std::array<double, 4>>& clip_planes = {},
                                  const std::vector<ReferenceMeshCut>& mesh_cuts = {});

// A sphere drawn with the lines: the CPU reference of the surface passes
// (shaders/sphere_surface.comp and the merge, shared/surface_push.h).
struct ReferenceSphere {
  std::array<double, 3> center = {0, 0, 0};  // world mm
  double radius = 1;                         // mm, > 0
  uint32_t id = 0;                           // written to the pixels it wins, as their fiber
};

// For every pixel, the eye ray through its centre (in double precision,
// from the camera's matrices) against every sphere: the nearer root, or the
// farther one where the nearer lies before the near plane; the hit's clip
// depth from viewProjectionD. A hit with depth in [0, 1] strictly nearer
// than what the frame holds (lines or an earlier sphere) wins the pixel:
// fiber = the sphere's id, point = 0, tangent = the outward unit normal.
// Throws Error for an invalid camera or a sphere whose radius is not > 0.
void rasterizeReferenceSpheres(ReferenceFrame& frame, const std::vector<ReferenceSphere>& spheres,
                               const Camera& camera);

// The cut range of `mesh` (closed, outward) seen by `camera`.
ReferenceMeshCut referenceMeshCut(const TriangleMesh& mesh, const Camera& camera, bool cull_inside);

// Orientation colour: |tangent| as RGB on a black background, alpha 255;
// row-major RGBA8, top row first.
std::vector<uint8_t> shadeOrientation(const ReferenceFrame& frame);

}  // namespace fibscope
