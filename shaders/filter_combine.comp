// Fiber filter, combine (shared/fiber_filter.h): one invocation per fiber
// turns its FilterHits, length and scalars into its kept bit
// (FiberFilter::evaluate: length within the limits, every scalar in its
// range, a vertex in every include, none in any exclude, the ordered
// includes in order). The kept words are cleared
// first; fibers of several datasets share words, hence atomicOr.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/render_buffers.glsl"
#include "glsl/filter_regions.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kFilterGroupSize

layout(push_constant, std430) uniform Push { FilterPassPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer KeptRef { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer ScalarRangesRef { FilterScalarRanges block; };

void main() {
  const uint fiber = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                     gl_LocalInvocationIndex;
  if (fiber >= pc.fiber_count) return;
  const uvec4 h = FilterHitsRef(pc.hits).hits[fiber];
  const float length_mm = FloatsRef(pc.lengths).values[fiber];
  bool kept = h.w != 0u && length_mm >= pc.min_length && length_mm <= pc.max_length;
  kept = kept && (h.x & pc.include_lo) == pc.include_lo && (h.y & pc.include_hi) == pc.include_hi;
  kept = kept && (h.x & pc.exclude_lo) == 0u && (h.y & pc.exclude_hi) == 0u;
  kept = kept && (pc.ordered_regions == 0u || h.z == kFilterOrderKept);
  if (pc.scalar_ranges != 0ul) {
    ScalarRangesRef ranges = ScalarRangesRef(pc.scalar_ranges);
    const uint count = min(ranges.block.count, kFilterMaxScalarRanges);
    for (uint r = 0u; r < count; ++r) {
      const FilterScalarRange range = ranges.block.ranges[r];
      const float value = FloatsRef(range.values).values[pc.fiber_base + fiber];
      kept = kept && filterScalarInRange(value, range.min, range.max);
    }
  }
  if (pc.has_zone != 0u) {
    const float d2 = uintBitsToFloat(FilterZoneRef(pc.zone_d2).words[fiber]);
    kept = kept && d2 <= pc.max_d2;
    // The distance in mm for colouring (a sphere's from its surface, 0 inside).
    FilterZoneMmRef(pc.zone_mm).values[fiber] = max(sqrt(d2) - pc.zone_radius, 0.0);
  }
  if (!kept) return;
  const uint g = pc.fiber_base + fiber;
  atomicOr(KeptRef(pc.kept).words[g >> 5u], 1u << (g & 31u));
}
