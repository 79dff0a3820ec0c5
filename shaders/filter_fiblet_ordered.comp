// Fiber filter, ordered includes (shared/fiber_filter.h): one invocation
// per fiber walks its vertices in order, fiblet after fiblet (the serial
// decode of filter_fiblet_hits.comp), through FiberFilter::evaluate's
// rule, and writes the verdict into its FilterHits' z. Runs only when
// there are ordered includes: a walk per fiber is the slow shape on a GPU.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/fiblet_record.glsl"
#include "glsl/filter_fiblet.glsl"
#include "glsl/filter_regions.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kFilterGroupSize

layout(push_constant, std430) uniform Push { FilterPassPush pc; };

void main() {
  const FibletDataset ds = DatasetRef(pc.source).ds;
  const uint fiber = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                     gl_LocalInvocationIndex;
  if (fiber >= ds.fiber_count) return;
  UintsRef first = UintsRef(ds.fiber_first_fiblet);
  const uint f0 = first.values[fiber], f1 = first.values[fiber + 1u];
  FilterRegionsRef regions = FilterRegionsRef(pc.regions);
  const uint o = pc.hit_regions, m = pc.ordered_regions;
  const uint n = ds.points_per_fiblet;
  WordsRef records = WordsRef(ds.records);
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  DirectionsRef directions = DirectionsRef(ds.directions);
  uvec2 state = uvec2(0u, 1u);
  for (uint fiblet = f0; fiblet < f1 && state.y != 0u; ++fiblet) {
    const uint base = fiblet * ds.record_words;
    const uint count = fibletCount(fibletRecordByte(records, base, fibletFlagsByte(n)));
    if (count < 1u || count > n) continue;
    const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
    const vec3 p0_n = fibletRecordPoint(w0, w1, w2, 0u);
    // A fiblet far from every ordered region leaves the walk as it is (its
    // points lie in none of them).
    vec3 c;
    float radius;
    filterFibletSphere(ds, fiblet, count, p0_n, fibletRecordPoint(w0, w1, w2, 1u), c, radius);
    if (!filterSphereNearAny(regions, o, m, c, radius)) continue;
    const bool first_fiblet = fiblet == f0, last_fiblet = fiblet + 1u == f1;
    if (pc.ends_only == 0u || first_fiblet) {
      state = filterOrderedStep(regions, o, m, fibletToWorld(ds, p0_n), state);
    }
    if (pc.ends_only != 0u && !last_fiblet) continue;
    if (count < 2u) {
      // A one-point last fiblet: its point is also the fiber's last.
      if (pc.ends_only != 0u) state = filterOrderedStep(regions, o, m, fibletToWorld(ds, p0_n), state);
      continue;
    }
    FibletTransform s = fibletInitialTransform(p0_n, fibletRecordPoint(w0, w1, w2, 1u), v);
    for (uint k = 0u; k + 1u < count; ++k) {
      if (k > 0u) s = fibletNextTransform(s, directions, records, base, k);
      if (pc.ends_only == 0u || k + 2u == count) state = filterOrderedStep(regions, o, m, fibletToWorld(ds, s.t), state);
    }
  }
  const bool kept = state.y != 0u && state.x == m;  // (a fiber without points: the combine drops it)
  FilterHitsRef(pc.hits).hits[fiber].z = kept ? kFilterOrderKept : 0u;
}
