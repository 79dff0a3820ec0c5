// SVO streamtubes (McGraw, "High-quality real-time raycasting and
// raytracing of streamtubes with sparse voxel octrees"; issue 16): the
// octree's node layout, the voxel grid, the ordered-float and Morton
// helpers, and the push constants of the voxelisation, radix-sort and
// ray-tracing passes, shared by src/svo and shaders/svo_*.comp,
// shaders/radix_*.comp.
//
// Tubes are the tube model's segments (shared/tubes.h TubeNode and
// TubeSegment, src/tubes/tube_model.h) taken as straight capsules: the
// segment between its two nodes' centres, of radius the mean of the two
// node radii (constant for constant and per-fiber radius sources).
//
// The grid: side = 2^levels voxels a side (levels <= kSvoMaxLevels),
// voxel (i, j, k) centred at origin + (i + 1/2, j + 1/2, k + 1/2) * voxel.
// The signed distance of the union of capsules (seed eq. 1: distance to
// the segment minus r, union by min) is sampled at voxel centres; a voxel
// is a leaf where |f| < band, band = kSvoBandScale * voxel (just over half
// the voxel's diagonal: every voxel the union's surface passes through is a
// leaf, f being 1-Lipschitz; likewise a segment is in a leaf's list where
// its own |f_s| < band, so every surface point of it inside the voxel is
// found there).
#ifndef FIBSCOPE_SHADERS_SHARED_SVO_H
#define FIBSCOPE_SHADERS_SHARED_SVO_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define SVO_CONST inline constexpr
#else
#define SVO_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// 1024^3 voxels at most: Morton codes of 30 bits.
SVO_CONST uint kSvoMaxLevels = 10u;
// band / voxel: sqrt(3) / 2 (half the diagonal) with a 1 % margin.
SVO_CONST float kSvoBandScale = 0.8748f;
// The ordered key of "no tube near": above every finite float's key.
SVO_CONST uint kSvoFar = 0xFFFFFFFFu;

// Curved tubes (svo-curved; src/svo/svo_build.h curveDistance,
// glsl/svo_curve.glsl): the nearest point of a cubic segment from
// kSvoCurveSamples + 1 samples and kSvoCurveNewtonSteps Newton steps; the
// sphere tracing in a leaf takes at most kSvoSphereSteps steps and hits
// where the union's distance is below kSvoHitEpsilon * voxel.
SVO_CONST uint kSvoCurveSamples = 8u;
SVO_CONST uint kSvoCurveNewtonSteps = 4u;
SVO_CONST uint kSvoSphereSteps = 48u;
SVO_CONST float kSvoHitEpsilon = 1e-3f;

// Node reference word: the type in the top two bits, an index below.
SVO_CONST uint kSvoNodeEmpty = 0u;             // no leaf below
SVO_CONST uint kSvoNodeInternal = 0x40000000u; // index: node index of child 0 of its 2x2x2 block
SVO_CONST uint kSvoNodeLeaf = 0x80000000u;     // index: word offset of its list in the decoration data
SVO_CONST uint kSvoNodeTypeMask = 0xC0000000u;
SVO_CONST uint kSvoNodeIndexMask = 0x3FFFFFFFu;

// One octree node (8 bytes). Node 0 is the root; the 8 children of an
// internal node are one block at ref's index, child c = x | y << 1 | z << 2
// (the low bits of the Morton code). A leaf's decoration list: the word
// count n, then n segment indices (TubeSegment records), every segment that
// touches the leaf.
struct SvoNode {
  uint ref;        // kSvoNode* | index
  float distance;  // leaf: f at its centre (mm); else 0
};

// Ordered-integer encoding of a float for atomicMin (a < b iff key(a) <
// key(b) for non-NaN floats): flips all bits of negatives, the sign bit of
// positives.
SHADER_FN uint svoOrderedKey(float f) {
  uint b = floatBitsToUint(f);
  return (b & 0x80000000u) != 0u ? ~b : (b | 0x80000000u);
}
SHADER_FN float svoKeyFloat(uint k) {
  return uintBitsToFloat((k & 0x80000000u) != 0u ? (k & 0x7FFFFFFFu) : ~k);
}

// 10 bits of v spread to every third bit.
SHADER_FN uint svoSpreadBits(uint v) {
  v &= 0x3FFu;
  v = (v | (v << 16u)) & 0x030000FFu;
  v = (v | (v << 8u)) & 0x0300F00Fu;
  v = (v | (v << 4u)) & 0x030C30C3u;
  v = (v | (v << 2u)) & 0x09249249u;
  return v;
}
SHADER_FN uint svoMorton(uint x, uint y, uint z) {
  return svoSpreadBits(x) | (svoSpreadBits(y) << 1u) | (svoSpreadBits(z) << 2u);
}

// Workgroup sizes.
SVO_CONST uint kSvoVoxelizeGroupSize = 64u;  // one workgroup per segment
SVO_CONST uint kSvoCompactGroupSize = 256u;  // one invocation per voxel of the slab
SVO_CONST uint kRadixBlock = 256u;           // keys per workgroup of the histogram and scatter passes
SVO_CONST uint kRadixDigits = 16u;           // 4 bits per pass
SVO_CONST uint kSvoTraceTile = 8u;           // 8 x 8 pixels per workgroup

// svo_voxelize.comp: workgroup g takes segment g (or list[g]); its invocations walk the
// voxels of the segment's box (widened by r + band) inside the slab
// z in [slab_z0, slab_z0 + slab_depth) and atomicMin svoOrderedKey(f_s) into
// field[((z - slab_z0) * rows + y) * side + x] where f_s < band (rows =
// side unless given).
struct SvoVoxelizePush {
  uint64_t nodes;     // TubeNode[]
  uint64_t segments;  // TubeSegment[]
  uint64_t field;     // uint per voxel of the slab; kSvoFar before the pass
  // uint[segment_count]: the segments to splat, workgroup g taking
  // list[g] (the octree build's segments whose band reaches the slab); 0:
  // workgroup g takes segment g.
  uint64_t list;
  float origin_x, origin_y, origin_z;  // grid origin (mm)
  float voxel;                         // voxel size (mm)
  uint side;
  uint slab_z0;
  uint slab_depth;
  uint segment_count;
  float band;
  uint curved;  // 1: curved tubes (glsl/svo_curve.glsl), 0: capsules
  // The field's y extent when it is not `side` (the distance field of
  // shared/distance_field.h: side x rows x slab_depth voxels, rows the y
  // stride); 0: side. z is bounded by the slab alone.
  uint rows;
  uint pad2;
};

// svo_compact.comp: one invocation per voxel of the slab: where
// |f| < band, appends (Morton code, f's bits) at slot atomicAdd(count, 1)
// (written only below capacity; count keeps counting, so an overflow tells
// the size needed).
struct SvoCompactPush {
  uint64_t field;
  uint64_t keys;       // uint[capacity]
  uint64_t values;     // uint[capacity]: floatBitsToUint(f)
  uint64_t count;      // uint, not cleared by the pass
  uint side;
  uint slab_z0;
  uint slab_depth;
  uint capacity;
  float band;
  uint pad0;
  uint pad1;
  uint pad2;
};

// The LSD radix sort of (key, value) pairs, 4 bits a pass, stable:
//   radix_histogram.comp  block b's count of each digit -> counts[digit * blocks + b]
//   radix_scan.comp       exclusive scan of counts in that order, in chunks of kRadixScanChunk
//   radix_scan_add.comp   (RadixScanPush): each chunk scanned by one workgroup, the chunks'
//                         totals scanned likewise one level up, and added back to their chunks
//   radix_scatter.comp    each key to counts[digit * blocks + b] + its rank among the block's
//                         earlier keys of the same digit
SVO_CONST uint kRadixScanGroup = 256u;                      // invocations of a scan workgroup
SVO_CONST uint kRadixScanChunk = 4u * kRadixScanGroup;      // counts one scan workgroup takes (4 each)
// radix_scan.comp: the exclusive scan of data[chunk * kRadixScanChunk ..]
// (count words in all) in place per chunk, each chunk's total to
// sums[chunk]; radix_scan_add.comp: adds sums[chunk] (by then scanned) to
// its chunk's words.
struct RadixScanPush {
  uint64_t data;  // uint[count]
  uint64_t sums;  // uint[ceil(count / kRadixScanChunk)]
  uint count;
  uint pad0;
  uint pad1;
  uint pad2;
};
struct RadixPush {
  uint64_t keys_in;
  uint64_t values_in;
  uint64_t keys_out;
  uint64_t values_out;
  uint64_t counts;  // uint[kRadixDigits * blocks]
  uint count;       // keys
  uint shift;       // bit of the pass's digit
  uint blocks;
  uint pad0;
};

// svo_trace.comp: one invocation per pixel: the eye ray through the pixel
// centre walks the octree (push-down kd-restart, the seed's Algorithm 1,
// for octrees) leaf by leaf; in each leaf it intersects the list's
// capsules exactly and takes the nearest hit inside the leaf's stretch of
// the ray; the first leaf with one ends the walk. Kept where its clip
// depth lies in [0, 1] and is nearer than the surface texel's. Curved: in
// each leaf, sphere tracing of the union of the list's curved-tube
// distances from the leaf's entry (at most kSvoSphereSteps steps), a hit
// where it falls below kSvoHitEpsilon * voxel within the leaf's stretch.
//
// Level of detail (lod_px > 0; issue 16 item 3, the seed's future work):
// an internal node whose edge is below lod_px pixel footprints at the
// ray's current point (edge < lod_px * pixel_angle * t) is not descended:
// it is taken as hit (it holds a leaf) by its representative segment,
// svo_lod[block], block = (child block's node index - 1) / 8 (every
// internal node owns exactly one child block and the blocks follow the
// root in order, so this numbers the internal nodes densely). The hit
// point lies in the node's stretch of the ray. The error, stated: depth
// (along the ray) at most the node's diagonal sqrt(3) * edge before the
// nearest true surface in that node, which is < sqrt(3) * lod_px pixel
// footprints at that depth; coverage only grows (every pixel the exact
// walk covers stays covered) and by at most the nodes' projection around
// the tubes (< sqrt(3) * lod_px + 1 pixels). lod_px = 0: the exact walk,
// bit for bit.
struct SvoTracePush {
  uint64_t camera;      // CameraBlock
  uint64_t svo_nodes;   // SvoNode[]
  uint64_t decoration;  // uint[]
  uint64_t nodes;       // TubeNode[]
  uint64_t segments;    // TubeSegment[]
  uint64_t surface;     // SurfaceTexel per pixel (read and written)
  float origin_x, origin_y, origin_z;  // the grid
  float voxel;
  uint levels;
  uint width;
  uint height;
  uint curved;  // 1: sphere-trace the leaf's curved tubes (svo-curved), 0: exact capsules
  float lod_px;       // 0: off
  float pixel_angle;  // a pixel's footprint per mm along the ray (2 tan(fov_y / 2) / height)
  uint64_t svo_lod;   // uint per internal node: its representative segment (read only when lod_px > 0)
  // uint[2] (0: none): += the walk's node visits and the segments it
  // tests (capsule intersections or curved-distance evaluations), for
  // tests and benchmarks; one atomic per pixel when set.
  uint64_t stats;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::SvoNode) == 8, "an octree node is 8 bytes");
static_assert(sizeof(fibscope::shader::SvoVoxelizePush) == 80, "");
static_assert(offsetof(fibscope::shader::SvoVoxelizePush, side) == 48, "");
static_assert(sizeof(fibscope::shader::SvoCompactPush) == 64, "");
static_assert(sizeof(fibscope::shader::RadixPush) == 56, "");
static_assert(sizeof(fibscope::shader::RadixScanPush) == 32, "");
static_assert(sizeof(fibscope::shader::SvoTracePush) == 104, "");
static_assert(offsetof(fibscope::shader::SvoTracePush, svo_lod) == 88, "");
static_assert(offsetof(fibscope::shader::SvoTracePush, levels) == 64, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_SVO_H
