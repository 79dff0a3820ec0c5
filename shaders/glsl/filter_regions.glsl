// The regions of the fiber filter's passes (shared/fiber_filter.h): a
// vertex tested against one region, and against every hit region at once.
#ifndef FIBSCOPE_GLSL_FILTER_REGIONS_GLSL
#define FIBSCOPE_GLSL_FILTER_REGIONS_GLSL

#include "shared/fiber_filter.h"
#include "shared/voxel_mask.h"

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer FilterRegionsRef { FilterRegion regions[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer FilterHitsRef { uvec4 hits[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer FilterMaskRef { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer FilterZoneRef { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) writeonly buffer FilterZoneMmRef { float values[]; };

// kFilterMask: the voxel p falls in by MRtrix3 tckedit's rule
// (shared/voxel_mask.h, as the CPU's VoxelMask::contains); outside the
// grid is outside.
bool filterMaskContains(FilterRegion r, vec3 p) {
  const float x = roundHalfAwayFromZero(voxelMaskCoordinate(vec4(r.v[0], r.v[1], r.v[2], r.v[3]), p));
  const float y = roundHalfAwayFromZero(voxelMaskCoordinate(vec4(r.v[4], r.v[5], r.v[6], r.v[7]), p));
  const float z = roundHalfAwayFromZero(voxelMaskCoordinate(vec4(r.v[8], r.v[9], r.v[10], r.v[11]), p));
  if (!(x >= 0.0 && y >= 0.0 && z >= 0.0 && x < float(r.nx) && y < float(r.ny) && z < float(r.nz))) return false;
  const uint i = uint(x) + r.nx * (uint(y) + r.ny * uint(z));
  return ((FilterMaskRef(r.mask).words[i >> 5u] >> (i & 31u)) & 1u) != 0u;
}

bool filterRegionContains(FilterRegion r, vec3 p) {
  if (r.kind == kFilterSphere) return filterSphereContains(r.v[0], r.v[1], r.v[2], r.v[3], p);
  if (r.kind == kFilterBox) return filterBoxContains(r.v[0], r.v[1], r.v[2], r.v[3], r.v[4], r.v[5], p);
  if (r.kind == kFilterOrientedBox)
    return filterOrientedBoxContains(vec3(r.v[0], r.v[1], r.v[2]), vec3(r.v[3], r.v[4], r.v[5]),
                                     vec3(r.v[6], r.v[7], r.v[8]), vec3(r.v[9], r.v[10], r.v[11]),
                                     vec3(r.v[12], r.v[13], r.v[14]), p);
  return filterMaskContains(r, p);
}

// The hit regions (the first `count` of `regions`) p lies in, as bits.
uvec2 filterHitBits(FilterRegionsRef regions, uint count, vec3 p) {
  uvec2 bits = uvec2(0u);
  for (uint i = 0u; i < count; ++i)
    if (filterRegionContains(regions.regions[i], p)) {
      if (i < 32u) bits.x |= 1u << i;
      else bits.y |= 1u << (i - 32u);
    }
  return bits;
}

// The ordered includes' walk (FiberFilter::evaluate): the first ordered
// region p lies in must be the next one to enter or the one entered last.
// state: x = next to enter, y = 1 while in order.
uvec2 filterOrderedStep(FilterRegionsRef regions, uint first, uint count, vec3 p, uvec2 state) {
  if (state.y == 0u) return state;
  for (uint k = 0u; k < count; ++k)
    if (filterRegionContains(regions.regions[first + k], p)) {
      if (k == state.x) state.x += 1u;
      else if (k + 1u != state.x) state.y = 0u;
      break;
    }
  return state;
}

// The squared distance of p to the zone (FilterPassPush: the region after
// the hit and ordered ones).
float filterZoneDistance2(FilterRegion z, vec3 p) {
  return filterDistance2(z.kind, z.v[0], z.v[1], z.v[2], z.v[3], z.v[4], z.v[5], vec3(z.v[6], z.v[7], z.v[8]),
                         vec3(z.v[9], z.v[10], z.v[11]), vec3(z.v[12], z.v[13], z.v[14]), p);
}

// Whether the sphere (c, r) reaches the box of any of `count` regions from
// `first`: when it does not, no point inside the sphere lies in any.
bool filterSphereNearAny(FilterRegionsRef regions, uint first, uint count, vec3 c, float r) {
  for (uint i = first; i < first + count; ++i) {
    const FilterRegion g = regions.regions[i];
    const vec3 lo = vec3(g.box[0], g.box[1], g.box[2]), hi = vec3(g.box[3], g.box[4], g.box[5]);
    const vec3 d = max(max(lo - c, c - hi), vec3(0.0));
    if (dot(d, d) <= r * r) return true;
  }
  return false;
}

#endif
