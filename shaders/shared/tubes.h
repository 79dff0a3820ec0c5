// Spline tubes (Salm, "Interactive Rendering of Spline Tubes"; issue 15):
// the tubes buffer shared by the C++ model (src/tubes/tube_model.h) and the
// shaders, and the push constants of the compute ray caster.
//
// The tubes buffer (the seed's figure 3): node records (TubeNode, one per
// node of every tube, tube after tube) and segment records (TubeSegment,
// one per pair of consecutive nodes of a tube, holding the index of its
// first node), so every segment of every tube is one item of one dispatch
// or one instanced draw.
//
// A segment is the cubic Hermite curve between its two nodes, parameter
// u in [0, 1], with end derivatives length * tangent (the node tangents
// are per mm of arc, TubeNode). The ray caster splits it into two
// quadratic Bezier sub-segments (tubeQuadratic below): sub-segment k of
// segment s is item 2 s + k.
#ifndef FIBSCOPE_SHADERS_SHARED_TUBES_H
#define FIBSCOPE_SHADERS_SHARED_TUBES_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define TUBE_CONST inline constexpr
#else
#define TUBE_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// Screen tiles of the compute ray caster (kTubeTileSize^2 pixels, one
// workgroup each). A thin tube crosses a number of sub-segments per tile
// proportional to the tile's side, which every pixel of the tile then
// tests: 8 px tiles cast 300 phantom tubes (22,620 segments, 800 x 600,
// lavapipe) in 2.4 s against 4.8 s with 16 px tiles.
//
// The tiles' lists are packed end to end in one buffer (counted, scanned,
// filled: tube_bin_count, tube_bin_offsets, tube_bin_fill), so a tile holds
// as many sub-segments as reach it. The buffer starts at
// kTubeTileCapacity items a tile and grows to the frame's total for the
// next frame, up to a byte limit; a tile whose list ends past the buffer
// tests every sub-segment instead (slow, never wrong) and is counted
// (FrameStats::tube_tiles_overflowed).
TUBE_CONST uint kTubeTileSize = 8u;
TUBE_CONST uint kTubeTileCapacity = 512u;
// Invocations of the offsets pass (one workgroup over every tile).
TUBE_CONST uint kTubeScanGroupSize = 256u;
// Sub-segments per workgroup of the binning pass.
TUBE_CONST uint kTubeBinGroupSize = 64u;
// The colour slope of a node (TubeNode::color_slope) is stored as
// packSnorm4x8 of (d colour / ds) / kTubeColorSlopeMax, colour in [0, 1]
// per channel, s in mm: steeper slopes are clamped.
TUBE_CONST float kTubeColorSlopeMax = 1.0f;

// One node of a tube (48 bytes).
struct TubeNode {
  vec4 position_radius;  // xyz: centre (world mm); w: radius (mm, > 0)
  vec4 tangent_dradius;  // xyz: dP/ds, the unit tangent per mm of arc; w: dr/ds
  uint color;            // RGBA8 own colour, used when A > 0 (else the colour mode's)
  uint color_slope;      // d colour / ds, packSnorm4x8 over kTubeColorSlopeMax
  float point;           // position along the fiber, in its original points from the first
  uint normal;           // rotation-minimising frame's first axis (unit, normal to the tangent), packed octahedral
};

// One Hermite segment between nodes `node` and `node + 1` (16 bytes).
struct TubeSegment {
  uint node;     // index of the first node in the node records
  uint fiber;    // the fiber's id (G-buffer fiber field, picking)
  float chord;   // chord length |P1 - P0| in mm: the Hermite end derivatives are length * tangent
  uint pad0;
};

// A quadratic Bezier sub-segment of the sphere-swept model: the union of
// the spheres of centre c(t) and radius r(t), t in [0, 1], both quadratic
// Bezier in t with control points b0, b1, b2 (xyz centre, w radius).
struct TubeQuadratic {
  vec4 b0;
  vec4 b1;
  vec4 b2;
};

// Sub-segment `which_half` (0: u in [0, 1/2], 1: u in [1/2, 1]) of the Hermite
// segment from node a to node b of chord length `chord`. The two inner
// control points are the Hermite's end points moved a quarter of the end
// derivatives inward and the join is their midpoint, which is the cubic's
// own point at u = 1/2: so the pair passes through both nodes with the
// node tangents' directions (C1 along a tube, since neighbouring segments
// share the node's derivative) and through the cubic's midpoint. Radius
// the same way from dr/ds.
SHADER_FN TubeQuadratic tubeQuadratic(TubeNode a, TubeNode b, float chord, uint which_half) {
  SHADER_PRECISE float q = 0.25f * chord;
  SHADER_PRECISE vec3 p0 = vec3(a.position_radius.x, a.position_radius.y, a.position_radius.z);
  SHADER_PRECISE vec3 p1 = vec3(b.position_radius.x, b.position_radius.y, b.position_radius.z);
  SHADER_PRECISE vec3 c0 = p0 + vec3(a.tangent_dradius.x, a.tangent_dradius.y, a.tangent_dradius.z) * q;
  SHADER_PRECISE vec3 c1 = p1 - vec3(b.tangent_dradius.x, b.tangent_dradius.y, b.tangent_dradius.z) * q;
  SHADER_PRECISE vec3 m = (c0 + c1) * 0.5f;
  SHADER_PRECISE float r0 = a.position_radius.w;
  SHADER_PRECISE float r1 = b.position_radius.w;
  SHADER_PRECISE float rc0 = r0 + a.tangent_dradius.w * q;
  SHADER_PRECISE float rc1 = r1 - b.tangent_dradius.w * q;
  SHADER_PRECISE float rm = (rc0 + rc1) * 0.5f;
  TubeQuadratic out_q;
  if (which_half == 0u) {
    out_q.b0 = vec4(p0, r0);
    out_q.b1 = vec4(c0, rc0);
    out_q.b2 = vec4(m, rm);
  } else {
    out_q.b0 = vec4(m, rm);
    out_q.b1 = vec4(c1, rc1);
    out_q.b2 = vec4(p1, r1);
  }
  return out_q;
}

// tube_bin_count.comp and tube_bin_fill.comp: one invocation per
// sub-segment: its box (the quadratic's exact extent per axis, widened by
// its largest radius control) projected to the screen (glsl/tube_bin.glsl);
// the count pass adds one to every tile the projection overlaps, the fill
// pass appends the sub-segment to those tiles' lists (tile_ends[tile], the
// list's start after the offsets pass, is its cursor and ends as the list's
// end).
struct TubeBinPush {
  uint64_t camera;       // CameraBlock
  uint64_t nodes;        // TubeNode[]
  uint64_t segments;     // TubeSegment[]
  uint64_t tile_counts;  // uint per tile, then the overflowing tiles, then the total; cleared to 0 before the count
  uint64_t tile_ends;    // uint per tile: written by the offsets pass, advanced by the fill
  uint64_t tile_lists;   // uint[list_capacity]: sub-segment indices, tile after tile
  uint sub_segments;     // 2 * segments
  uint tiles_x;
  uint tiles_y;
  uint list_capacity;    // items the lists buffer holds
};

// tube_bin_offsets.comp: one workgroup of kTubeScanGroupSize: the exclusive
// prefix sum of the tiles' counts into tile_ends (each list's start), the
// total into tile_counts[tiles + 1] and the number of tiles whose list ends
// past list_capacity into tile_counts[tiles].
struct TubeBinOffsetsPush {
  uint64_t tile_counts;
  uint64_t tile_ends;
  uint tiles;
  uint list_capacity;
};

// tube_raycast.comp: one invocation per pixel, workgroups of one tile: the
// eye ray through the pixel centre against every sub-segment of its tile's
// list (tile_ends[tile] - tile_counts[tile] to tile_ends[tile]; all of them
// where the list ends past list_capacity), the front intersection
// of the sphere-swept model (tubeIntersect in glsl/tube_intersect.glsl;
// its CPU reference src/tubes/tube_intersect.h), kept where its clip depth
// lies in [0, 1] and is nearer than the surface texel's.
struct TubeRaycastPush {
  uint64_t camera;
  uint64_t nodes;
  uint64_t segments;
  uint64_t tile_counts;
  uint64_t tile_ends;
  uint64_t tile_lists;
  uint64_t surface;  // SurfaceTexel per pixel (read and written)
  uint sub_segments;
  uint tiles_x;
  uint width;
  uint height;
  uint list_capacity;
  uint pad0;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::TubeNode) == 48, "a tube node is 12 words");
static_assert(offsetof(fibscope::shader::TubeNode, color) == 32, "");
static_assert(sizeof(fibscope::shader::TubeSegment) == 16, "a tube segment is 4 words");
static_assert(sizeof(fibscope::shader::TubeQuadratic) == 48, "");
static_assert(sizeof(fibscope::shader::TubeBinPush) == 64, "");
static_assert(offsetof(fibscope::shader::TubeBinPush, sub_segments) == 48, "");
static_assert(sizeof(fibscope::shader::TubeBinOffsetsPush) == 24, "");
static_assert(sizeof(fibscope::shader::TubeRaycastPush) == 80, "");
static_assert(offsetof(fibscope::shader::TubeRaycastPush, sub_segments) == 56, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_TUBES_H
