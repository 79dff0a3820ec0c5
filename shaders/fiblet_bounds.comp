// Exact bounding spheres of the fiblets (DESIGN.md section 6, step 1), run
// once per dataset, in the first frame that culls by occlusion
// (render/gpu/fiblet_bounds.h, GpuDataset::recordFibletBoundsOnce): one
// invocation per fiblet decodes it front to back exactly as
// fiblet_raster_serial.comp does (W_1, then W_1 L_2 ... L_k, points in
// normalised units, then fibletToWorld) and writes one vec4 to the
// dataset's fiblet_bounds: the world-space centre of the axis-aligned box of
// the points it draws (its decoded points, and the next fiblet's first point
// when the joining segment is its own) and the largest distance from that
// centre to any of them, enlarged by fibletBoundsSlack (shared/cull_push.h)
// for the rounding by which the other rasters' decode orders differ.
// A fiblet that draws nothing (a single point ending its fiber, or a record
// the rasters refuse) gets radius -1: the cull skips it as before.
//
// The box centre is not the smallest enclosing sphere's, but for the nearly
// straight runs a fiblet is made of it lies within a few percent of it, and
// it costs one pass over the points plus one over their distances (the
// points are decoded twice rather than stored: 60 x 12 bytes per invocation
// would spill on every device).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/cull_push.h"
#include "glsl/fiblet_record.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kCullGroupSize

layout(push_constant, std430) uniform Push { FibletBoundsPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer BoundsOutRef { vec4 spheres[]; };

void main() {
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  const uint fiblet = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
  if (fiblet >= ds.fiblet_count) return;
  BoundsOutRef bounds = BoundsOutRef(pc.bounds);
  const uint n = ds.points_per_fiblet;
  WordsRef records = WordsRef(ds.records);
  const uint base = fiblet * ds.record_words;
  const uint flags = fibletRecordByte(records, base, fibletFlagsByte(n));
  const uint count = fibletCount(flags);
  const bool joins = (flags & kFibletFlagEnds) == 0u && fiblet + 1u < ds.fiblet_count;
  if (count < 1u || count > n || (count < 2u && !joins)) {
    bounds.spheres[fiblet] = vec4(0.0, 0.0, 0.0, -1.0);
    return;
  }
  const uint w0 = records.words[base], w1 = records.words[base + 1u], w2 = records.words[base + 2u];
  const vec3 p0_n = fibletRecordPoint(w0, w1, w2, 0u);
  const vec3 p0 = fibletToWorld(ds, p0_n);
  const vec3 p1_n = fibletRecordPoint(w0, w1, w2, 1u);
  const vec3 v = vec3(ds.v_x, ds.v_y, ds.v_z);
  DirectionsRef directions = DirectionsRef(ds.directions);
  const vec3 q = joins ? fibletToWorld(ds, fibletFirstPoint(records, base + ds.record_words)) : p0;

  // Pass 1: the box. Transform k gives point k + 1 (W_1 for k = 0, then
  // composed with L_{k+1}), as in fiblet_raster_serial.comp.
  vec3 lo = min(p0, q), hi = max(p0, q);
  FibletTransform s = fibletInitialTransform(p0_n, p1_n, v);
  for (uint k = 0u; k + 1u < count; ++k) {
    if (k > 0u) s = fibletNextTransform(s, directions, records, base, k);
    const vec3 p = fibletToWorld(ds, s.t);
    lo = min(lo, p);
    hi = max(hi, p);
  }
  const vec3 centre = 0.5 * (lo + hi);

  // Pass 2: the farthest point from the centre, squared distances (one
  // square root at the end).
  float far2 = max(dot(p0 - centre, p0 - centre), dot(q - centre, q - centre));
  s = fibletInitialTransform(p0_n, p1_n, v);
  for (uint k = 0u; k + 1u < count; ++k) {
    if (k > 0u) s = fibletNextTransform(s, directions, records, base, k);
    const vec3 d = fibletToWorld(ds, s.t) - centre;
    far2 = max(far2, dot(d, d));
  }
  const float reach = ds.mm_per_unit + max(max(abs(ds.translation_x), abs(ds.translation_y)), abs(ds.translation_z));
  bounds.spheres[fiblet] = vec4(centre, fibletBoundsRadius(sqrt(far2), reach));
}
