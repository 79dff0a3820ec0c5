// Fiber filter, hits (shared/fiber_filter.h): one invocation per fiblet
// decodes its points serially (the order of every serial decoder, so they
// are the points the CPU decoder gives) and ORs the include and exclude
// regions they lie in into its fiber's FilterHits. With ends_only only the
// fiber's first point (point 0 of its first fiblet) and last point (the
// last point of its last fiblet) are tested. The hits are cleared first;
// w is set for every fiber that has a point.
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

void addHits(FilterHitsRef hits, uint fiber, uvec2 bits) {
  if (bits.x != 0u) atomicOr(hits.hits[fiber].x, bits.x);
  if (bits.y != 0u) atomicOr(hits.hits[fiber].y, bits.y);
}

void main() {
  const FibletDataset ds = DatasetRef(pc.source).ds;
  const uint fiblet = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                      gl_LocalInvocationIndex;
  if (fiblet >= ds.fiblet_count) return;
  const uint n = ds.points_per_fiblet;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  const uint count = fibletCount(fibletRecordByte(records, base, fibletFlagsByte(n)));
  if (count < 1u || count > n) return;
  const uint fiber = UintsRef(ds.fiblet_fiber).values[fiblet];
  FilterRegionsRef regions = FilterRegionsRef(pc.regions);
  FilterHitsRef hits = FilterHitsRef(pc.hits);
  // The fiber has a vertex (tckedit drops one of none: its length is NaN).
  hits.hits[fiber].w = 1u;
  if (pc.hit_regions == 0u && pc.has_zone == 0u) return;
  bool first_only = false, last_only = false;
  if (pc.ends_only != 0u) {
    UintsRef first = UintsRef(ds.fiber_first_fiblet);
    first_only = first.values[fiber] == fiblet;
    last_only = first.values[fiber + 1u] == fiblet + 1u;
    if (!first_only && !last_only && pc.has_zone == 0u) return;
  }
  const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
  const vec3 p0_n = fibletRecordPoint(w0, w1, w2, 0u);
  // Most fiblets lie far from every region: decoding them would find
  // nothing (unless a distance zone wants every point's distance).
  vec3 c;
  float radius;
  filterFibletSphere(ds, fiblet, count, p0_n, fibletRecordPoint(w0, w1, w2, 1u), c, radius);
  const bool test_regions = pc.hit_regions > 0u && filterSphereNearAny(regions, 0u, pc.hit_regions, c, radius);
  const bool zone = pc.has_zone != 0u;
  if (!test_regions && !zone) return;
  FilterRegion zone_region;
  if (zone) zone_region = regions.regions[pc.hit_regions + pc.ordered_regions];
  uvec2 bits = uvec2(0u);
  float d2 = 1.0 / 0.0;
  {
    const vec3 p = fibletToWorld(ds, p0_n);
    // Point 0 is the fiber's last too when it ends a fiber in a one-point fiblet.
    if (test_regions && (pc.ends_only == 0u || first_only || (last_only && count == 1u)))
      bits = filterHitBits(regions, pc.hit_regions, p);
    if (zone) d2 = filterZoneDistance2(zone_region, p);
  }
  const bool walk = zone || (test_regions && (pc.ends_only == 0u || last_only));
  if (count >= 2u && walk) {
    const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
    DirectionsRef directions = DirectionsRef(ds.directions);
    // Transform k gives point k + 1 (fiblet_bounds.comp's walk).
    FibletTransform s = fibletInitialTransform(p0_n, fibletRecordPoint(w0, w1, w2, 1u), v);
    for (uint k = 0u; k + 1u < count; ++k) {
      if (k > 0u) s = fibletNextTransform(s, directions, records, base, k);
      const vec3 p = fibletToWorld(ds, s.t);
      if (test_regions && (pc.ends_only == 0u || (last_only && k + 2u == count)))
        bits |= filterHitBits(regions, pc.hit_regions, p);
      if (zone) d2 = min(d2, filterZoneDistance2(zone_region, p));
    }
  }
  if (zone) atomicMin(FilterZoneRef(pc.zone_d2).words[fiber], floatBitsToUint(d2));
  addHits(hits, fiber, bits);
}
