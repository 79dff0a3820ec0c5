// Mesh cuts (the fiblets paper's section 5.1; DESIGN.md section 2): a
// closed surface mesh rendered into a front and a back depth buffer, which
// the rasters read per fragment (exact: a fragment inside the mesh's depth
// range is discarded, or one outside it) and the cull reads dilated to
// tiles (a fiblet whose every fragment would be discarded is not drawn).
// Shared by the shaders and the C++ that records the passes
// (render/gpu/cut_mesh_stage.cpp).
//
// Depths are clip z/w in [0, 1] as the visibility buffer's, stored as float
// bits in uint words (non-negative floats order as their bits, so
// atomicMin on the words is the float minimum); kCutDepthNone (+inf) where
// no triangle of that facing covers the pixel.
//
// One depth range per pixel and mesh: "inside" is [front, back] with front
// the nearest front-facing and back the nearest back-facing depth (front
// taken as 0 when the nearest back face comes first: the eye is inside).
// A concave mesh whose ray enters twice is cut by its first range only
// (the paper's limitation, said in docs).
#ifndef FIBSCOPE_SHADERS_SHARED_CUT_MESH_H
#define FIBSCOPE_SHADERS_SHARED_CUT_MESH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define CUT_CONST inline constexpr
#else
#define CUT_CONST const
#endif

SHADER_NAMESPACE_BEGIN

CUT_CONST uint kMaxCutMeshes = 4u;
CUT_CONST uint kCutDepthNone = 0x7F800000u;  // floatBitsToUint(+inf)
// The cull's dilation: depth ranges summarised per tile of this many pixels
// a side, over the tile and its 8 neighbours.
CUT_CONST uint kCutTileSize = 16u;
CUT_CONST uint kCutRasterGroupSize = 64u;  // cut_mesh_raster.comp: triangles per workgroup
CUT_CONST uint kCutTileGroupSize = 64u;    // cut_mesh_tiles.comp: tiles per workgroup

// CutTile::flags
CUT_CONST uint kCutTileAnyCovered = 1u;  // some pixel of the tile (or a neighbour) has a range
CUT_CONST uint kCutTileAllCovered = 2u;  // every pixel of the tile and its neighbours has one

// Per tile and mesh, over the tile and its neighbours: the farthest front
// and the nearest back of the pixels' ranges (flags say whether they all
// have one). A sphere whose depths lie within [max_front, min_back] over
// its tiles, all covered, is inside at every pixel; one whose tiles have no
// range at all is outside at every pixel.
struct CutTile {
  float max_front;
  float min_back;
  uint flags;
  uint pad0;
};

// Where a frame's cut buffers lie (CameraBlock::cut_* points at one): per
// mesh m, its front words, its back words (width * height each) and its
// tiles (tiles_x * tiles_y CutTile).
struct CutMeshFrame {
  uint64_t depths;  // uint words: mesh m front at m * 2 * pixels, back at (m * 2 + 1) * pixels
  uint64_t tiles;   // CutTile: mesh m at m * tiles_x * tiles_y
  uint mesh_count;
  uint inside_bits;  // bit m: mesh m culls what lies inside it (else what lies outside)
  uint tiles_x;
  uint tiles_y;
};

// cut_mesh_raster.comp: one invocation per triangle of one mesh.
struct CutMeshRasterPush {
  uint64_t camera;     // CameraBlock
  uint64_t positions;  // float x, y, z per vertex (world mm)
  uint64_t triangles;  // uint a, b, c per triangle (outward: counter-clockwise seen from outside)
  uint64_t front;      // uint words, width * height
  uint64_t back;
  uint triangle_count;
  uint pad0;
};

// cut_mesh_tiles.comp: one invocation per tile of one mesh.
struct CutMeshTilesPush {
  uint64_t front;
  uint64_t back;
  uint64_t tiles;
  uint width;
  uint height;
  uint tiles_x;
  uint tiles_y;
};

// Whether a fragment at clip depth z lies inside the range (front, back)
// of a pixel (the words as stored).
SHADER_FN bool cutInside(uint front_bits, uint back_bits, float z) {
  if (back_bits == kCutDepthNone) return false;
  const float back = uintBitsToFloat(back_bits);
  const float front = front_bits == kCutDepthNone ? 0.0f : uintBitsToFloat(front_bits);
  const float first = front <= back ? front : 0.0f;
  return z >= first && z <= back;
}

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::CutTile) == 16, "");
static_assert(sizeof(fibscope::shader::CutMeshFrame) == 32, "");
static_assert(sizeof(fibscope::shader::CutMeshRasterPush) == 48, "");
static_assert(sizeof(fibscope::shader::CutMeshTilesPush) == 40, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_CUT_MESH_H
