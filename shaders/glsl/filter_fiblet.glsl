// A fiblet's bounding sphere for the fiber filter's passes: the precomputed
// one when the dataset has them (fiblet_bounds.comp), else the cull's
// bound from the record alone (fiblet_cull.comp's fallback, without the
// joining point: the filter tests the fiblet's own points only), in world
// mm with the cull's slack for the rounding of the decode.
#ifndef FIBSCOPE_GLSL_FILTER_FIBLET_GLSL
#define FIBSCOPE_GLSL_FILTER_FIBLET_GLSL

#include "shared/cull_push.h"
#include "glsl/fiblet_record.glsl"

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer FilterBoundsRef { vec4 spheres[]; };

void filterFibletSphere(FibletDataset ds, uint fiblet, uint count, vec3 p0_n, vec3 p1_n, out vec3 c, out float r) {
  if (ds.fiblet_bounds != 0ul) {
    const vec4 s = FilterBoundsRef(ds.fiblet_bounds).spheres[fiblet];
    c = s.xyz;
    r = max(s.w, 0.0);
    return;
  }
  const float n = count >= 2u ? length(p1_n - p0_n) + float(count - 2u) * ds.delta : 0.0;
  const float reach = ds.mm_per_unit + max(max(abs(ds.translation_x), abs(ds.translation_y)), abs(ds.translation_z));
  c = fibletToWorld(ds, p0_n);
  r = n * ds.mm_per_unit * (1.0 + kCullRadiusSlack) + kCullBoundsSlack * reach;
}

#endif
