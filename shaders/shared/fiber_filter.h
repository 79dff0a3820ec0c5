// The fiber filter on the GPU (DESIGN.md section 2, "selection state"):
// the regions, pushes and per-fiber records of the kept-bit passes
// (src/select/gpu/gpu_fiber_filter.h records them), shared by the shaders
// and the C++ that fills them, and the region tests both sides run.
//
// The kept bits are those of select/fiber_filter.h (MRtrix3 tckedit's
// semantics), computed in parts that need no order between them:
//   hits     per fiblet (or per streamline of a raw tractogram): which
//            include and exclude regions one of its vertices lies in,
//            OR-ed into the fiber's FilterHits (atomicOr);
//   ordered  per fiber, serially over its vertices in order (only when
//            there are ordered includes: their rule is a walk, not a set);
//   combine  per fiber: kept = length in range, every scalar in its range,
//            every include reached, no exclude entered, the ordered
//            includes entered in order.
// Exclusion and inclusion are order-free (a vertex in a region is one
// whatever came before), so only the ordered walk needs the vertices in
// sequence; the hits pass runs over fiblets, 60 times more invocations
// than fibers, which a GPU needs to fill itself with a million fibers.
#ifndef FIBSCOPE_SHADERS_SHARED_FIBER_FILTER_H
#define FIBSCOPE_SHADERS_SHARED_FIBER_FILTER_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cstddef>
#define FILTER_CONST inline constexpr
#else
#define FILTER_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// FilterRegion::kind.
FILTER_CONST uint kFilterSphere = 0u;       // v0..2 centre, v3 radius
FILTER_CONST uint kFilterBox = 1u;          // v0..2 min, v3..5 max (as floats: see packBox in the C++)
FILTER_CONST uint kFilterOrientedBox = 2u;  // v0..2 centre, v3..5 half sizes, v6..14 the three unit axes
FILTER_CONST uint kFilterMask = 3u;         // v0..11 world -> voxel (3 rows of 4); mask: a bit per voxel

// Include and exclude regions together (one bit each in FilterHits), and
// ordered includes (the walk's state fits a byte).
FILTER_CONST uint kFilterMaxHitRegions = 64u;
FILTER_CONST uint kFilterMaxOrderedRegions = 64u;
FILTER_CONST uint kFilterGroupSize = 64u;  // invocations per workgroup of every filter pass
// Scalar ranges (per-fiber values from the file, select/scalar_range.h).
FILTER_CONST uint kFilterMaxScalarRanges = 16u;

// One region on the device (std430: the 64-bit member first, then 4-byte
// scalars only), 128 bytes.
struct FilterRegion {
  uint64_t mask;  // kFilterMask: uint words, bit (i % 32) of word i / 32 for voxel i = x + nx (y + ny z)
  uint kind;
  uint nx;  // kFilterMask: the mask's size in voxels
  uint ny;
  uint nz;
  uint pad0;
  uint pad1;
  float v[16];
  // A box around the region (world mm; min then max, rounded outward): a
  // fiblet whose bounding sphere misses every region's box has no vertex
  // in any, and the hits pass skips decoding it.
  float box[6];
  uint pad2;
  uint pad3;
};

// One scalar range: `values` holds a float per scene fiber (indexed by the
// scene-global fiber, fiber_base + f), kept when min <= value <= max
// (filterScalarInRange); open ends are -inf / +inf.
struct FilterScalarRange {
  uint64_t values;
  float min;
  float max;
};
// The ranges of one update (the push constants are full: FilterPassPush
// holds only this block's address, 0 without ranges).
struct FilterScalarRanges {
  FilterScalarRange ranges[kFilterMaxScalarRanges];
  uint count;
  uint pad0;
  uint pad1;
  uint pad2;
};

// Per fiber: x, y = the include / exclude regions one of its vertices lies
// in (bit r of the 64 for region r of FilterPassPush::regions); z = the
// ordered walk's verdict (kFilterOrderKept), w = 1 when it has a vertex
// (one of none is dropped, as tckedit drops it: its length is NaN).
FILTER_CONST uint kFilterOrderKept = 1u;

// Every filter pass's push constants (one struct: the passes share most of
// it). Fiber indices are the source's own (0 .. fiber_count - 1); the kept
// bits are scene-global: fiber f's bit is bit (fiber_base + f) % 32 of
// word (fiber_base + f) / 32.
struct FilterPassPush {
  uint64_t source;    // FibletDataset block (fiblet passes) or RawTractogram block (raw passes)
  uint64_t regions;   // FilterRegion x (hit_regions + ordered_regions): the hit ones first
  uint64_t hits;      // uvec4 per fiber
  uint64_t lengths;   // float per fiber (mm): the combine's length test
  uint64_t kept;      // uint words over the scene's fibers (combine writes, raw points reads)
  uint64_t point_bits;  // raw points: uint words, a bit per point of the raw tractogram
  uint fiber_count;
  uint fiber_base;
  uint hit_regions;      // include + exclude
  uint ordered_regions;  // after them in `regions`
  uint include_lo;       // which hit bits are includes (the rest are excludes)
  uint include_hi;
  uint exclude_lo;
  uint exclude_hi;
  uint ends_only;        // 1: only the first and the last vertex of a fiber count
  float min_length;      // the limits with tckedit's margin (FiberFilter::lengthRange)
  float max_length;
  // Distance to a zone: the zone is regions[hit_regions + ordered_regions]
  // when has_zone; per fiber the smallest squared distance (float bits,
  // atomicMin) in `zone_d2`, the distance in mm in `zone_mm` (combine), and
  // kept only within max_d2 (+inf: no threshold).
  uint has_zone;
  float max_d2;
  float zone_radius;  // a sphere zone's radius (its distances are |p - c| - r)
  uint64_t scalar_ranges;  // FilterScalarRanges (combine), 0: none
  uint64_t zone_d2;
  uint64_t zone_mm;
};

// The region tests, the same arithmetic on both sides (glsl_cpp.h's rules:
// +, -, * only, every temporary precise), so a vertex on a boundary is
// decided alike on the CPU and the GPU.

// As MRtrix3's ROI: |centre - p|^2 <= r^2 in float, the sum in this order.
SHADER_FN bool filterSphereContains(float cx, float cy, float cz, float r, vec3 p) {
  SHADER_PRECISE float dx = cx - p.x;
  SHADER_PRECISE float dy = cy - p.y;
  SHADER_PRECISE float dz = cz - p.z;
  SHADER_PRECISE float d2 = (dx * dx + dy * dy) + dz * dz;
  SHADER_PRECISE float r2 = r * r;
  return d2 <= r2;
}

// min <= p <= max per axis. The C++ box holds doubles: the floats here are
// min rounded up and max rounded down, so a float p compares with them
// exactly as with the doubles.
SHADER_FN bool filterBoxContains(float x0, float y0, float z0, float x1, float y1, float z1, vec3 p) {
  return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1 && p.z >= z0 && p.z <= z1;
}

// |(p - c) . axis_k| <= half_k for the three axes, in float.
SHADER_FN bool filterAxisWithin(vec3 d, float ax, float ay, float az, float half_size) {
  SHADER_PRECISE float s = (d.x * ax + d.y * ay) + d.z * az;
  return s <= half_size && -s <= half_size;
}
SHADER_FN bool filterOrientedBoxContains(vec3 c, vec3 half_size, vec3 a0, vec3 a1, vec3 a2, vec3 p) {
  SHADER_PRECISE vec3 d = vec3(p.x - c.x, p.y - c.y, p.z - c.z);
  return filterAxisWithin(d, a0.x, a0.y, a0.z, half_size.x) && filterAxisWithin(d, a1.x, a1.y, a1.z, half_size.y) &&
         filterAxisWithin(d, a2.x, a2.y, a2.z, half_size.z);
}

// A per-fiber scalar against its range, the bounds as floats (min rounded
// up, max rounded down from the doubles, so the float comparison is the
// double one). A NaN value fails both comparisons: it is dropped, as a
// fiber whose value is unknown cannot be said to lie in the range.
SHADER_FN bool filterScalarInRange(float value, float lo, float hi) { return value >= lo && value <= hi; }

// Distance to a zone (the fiblets paper's figure 11 e, f): the squared
// distance from p to the zone's core, without a square root (whose GPU
// precision is the implementation's), so a threshold decides alike on both
// sides: a point or a sphere's centre (a sphere's distance is then
// |p - c| - r, its threshold (t + r)^2), a box's or an oriented box's
// volume (0 inside).
SHADER_FN float filterClampedOut(float lo, float hi, float x) {
  SHADER_PRECISE float below = lo - x;
  SHADER_PRECISE float above = x - hi;
  return below > 0.0f ? below : (above > 0.0f ? above : 0.0f);
}
SHADER_FN float filterDistance2(uint kind, float v0, float v1, float v2, float v3, float v4, float v5, vec3 a0, vec3 a1,
                                vec3 a2, vec3 p) {
  if (kind == kFilterSphere) {
    SHADER_PRECISE float dx = p.x - v0;
    SHADER_PRECISE float dy = p.y - v1;
    SHADER_PRECISE float dz = p.z - v2;
    SHADER_PRECISE float d2 = (dx * dx + dy * dy) + dz * dz;
    return d2;
  }
  if (kind == kFilterBox) {
    SHADER_PRECISE float dx = filterClampedOut(v0, v3, p.x);
    SHADER_PRECISE float dy = filterClampedOut(v1, v4, p.y);
    SHADER_PRECISE float dz = filterClampedOut(v2, v5, p.z);
    SHADER_PRECISE float d2 = (dx * dx + dy * dy) + dz * dz;
    return d2;
  }
  // Oriented box: centre v0..2, half sizes v3..5, axes a0..a2.
  SHADER_PRECISE vec3 d = vec3(p.x - v0, p.y - v1, p.z - v2);
  SHADER_PRECISE float s0 = (d.x * a0.x + d.y * a0.y) + d.z * a0.z;
  SHADER_PRECISE float s1 = (d.x * a1.x + d.y * a1.y) + d.z * a1.z;
  SHADER_PRECISE float s2 = (d.x * a2.x + d.y * a2.y) + d.z * a2.z;
  SHADER_PRECISE float q0 = filterClampedOut(-v3, v3, s0);
  SHADER_PRECISE float q1 = filterClampedOut(-v4, v4, s1);
  SHADER_PRECISE float q2 = filterClampedOut(-v5, v5, s2);
  SHADER_PRECISE float d2 = (q0 * q0 + q1 * q1) + q2 * q2;
  return d2;
}

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::FilterRegion) == 128, "a filter region is 128 bytes in std430");
static_assert(offsetof(fibscope::shader::FilterRegion, v) == 32, "the floats follow the header");
static_assert(sizeof(fibscope::shader::FilterPassPush) == 128, "");
static_assert(offsetof(fibscope::shader::FilterPassPush, scalar_ranges) == 104, "");
static_assert(offsetof(fibscope::shader::FilterPassPush, zone_d2) == 112, "");
static_assert(sizeof(fibscope::shader::FilterScalarRange) == 16, "");
static_assert(sizeof(fibscope::shader::FilterScalarRanges) == 16 * fibscope::shader::kFilterMaxScalarRanges + 16, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_FIBER_FILTER_H
