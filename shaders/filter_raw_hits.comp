// Fiber filter over a raw tractogram (the baselines' input,
// shared/raw_tractogram.h): one invocation per streamline walks its float
// vertices, the file's own, and writes its whole FilterHits: the include
// and exclude regions reached, the ordered includes' verdict, w = 1 when
// it has a vertex. (Serial per streamline: these are the baselines; the
// compute pipeline's fiblets get the parallel hits pass.)
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/raw_tractogram.glsl"
#include "glsl/filter_regions.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kFilterGroupSize

layout(push_constant, std430) uniform Push { FilterPassPush pc; };

void main() {
  const RawTractogram t = RawTractogramRef(pc.source).t;
  const uint s = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationIndex;
  if (s >= t.streamline_count) return;
  RawOffsetsRef offsets = RawOffsetsRef(t.offsets);
  const uint64_t first = offsets.values[s], end = offsets.values[s + 1u];
  uvec4 h = uvec4(0u);
  if (end > first) {
    const RawChunk c = rawChunk(t, rawChunkOfPoint(t, first));
    FilterRegionsRef regions = FilterRegionsRef(pc.regions);
    const uint o = pc.hit_regions, m = pc.ordered_regions;
    uvec2 state = uvec2(0u, 1u);
    const uint64_t n = end - first;
    // ends_only: the first vertex, then the last (the same one for a single point).
    const uint64_t visits = pc.ends_only != 0u ? 2ul : n;
    for (uint64_t i = 0ul; i < visits; ++i) {
      const uint64_t j = first - c.first_point + (pc.ends_only != 0u ? (i == 0ul ? 0ul : n - 1ul) : i);
      const vec3 p = rawChunkPoint(c, j);
      h.xy |= filterHitBits(regions, o, p);
      if (m > 0u) state = filterOrderedStep(regions, o, m, p, state);
    }
    h.z = state.y != 0u && state.x == m ? kFilterOrderKept : 0u;
    h.w = 1u;
    if (pc.has_zone != 0u) {
      // Every point's distance, ends_only or not.
      const FilterRegion zone = regions.regions[o + m];
      float d2 = 1.0 / 0.0;
      for (uint64_t i = 0ul; i < n; ++i) d2 = min(d2, filterZoneDistance2(zone, rawChunkPoint(c, first - c.first_point + i)));
      FilterZoneRef(pc.zone_d2).words[s] = floatBitsToUint(d2);
    }
  }
  FilterHitsRef(pc.hits).hits[s] = h;
}
