// Cull (DESIGN.md section 6, step 1): one invocation per fiblet. The
// fiblet's bounding sphere is tested against the frustum dilated by the line
// width (paper eq. 5) and, in phase 2 of two-phase culling, against the
// max-depth pyramid of what phase 1 drew (in coverage mode, against the
// pyramid of the previous frame re-projected: coverage_reproject.comp, the
// same test, one pass); fiblets smaller on screen than
// lod_pixels go to the LoD list (drawn as one segment), the others to the
// full list. Modes and the argument for conservativeness: shared/cull_push.h.
//
// Bounding sphere: the dataset's precomputed one when it has them
// (FibletDataset::fiblet_bounds, fiblet_bounds.comp): centred on the
// middle of the fiblet's box, its radius the largest distance to a point
// the fiblet draws (its decoded points and the joining point), found by
// decoding exactly as the serial raster does and enlarged by
// fibletBoundsRadius's slack for the rounding by which the other decode
// orders differ (shared/cull_push.h). Every segment the rasters draw joins
// two of those points, and a sphere is convex, so it holds every segment;
// the tests below only ever ask whether something lies outside the sphere.
//
// Fallback without them, from the record alone: centre = the first point
// p0. The decoder places point 1 as stored and every later point delta from
// the previous one (a rotation of a unit direction), so point k lies within
// |p1 - p0| + (k - 1) * delta of p0; the joining segment ends at the next
// fiblet's first point, read exactly. The radius is the larger of the two
// bounds (not N * delta: the stored p1 need not be delta from p0, and a
// short fiblet gets a small sphere), with kCullRadiusSlack for rounding.
// About twice the precomputed radius for a straight fiblet.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/fiblet_cull.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kCullGroupSize

layout(push_constant, std430) uniform Push { FibletCullPush pc; };

// Appends are aggregated per workgroup: one global atomicAdd per list per
// group (no subgroup operations needed). 64 fiblets per group own exactly
// two words of the visible bits, so phase 2 rewrites them without atomics.
shared uint s_count[2];
shared uint s_base[2];
shared uint s_visible[2];

void main() {
  const uint local = gl_LocalInvocationIndex;
  if (local < 2u) {
    s_count[local] = 0u;
    s_visible[local] = 0u;
  }
  barrier();

  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint fiblet = group * 64u + local;
  BitsRef bits = BitsRef(pc.visible);
  bool visible = false;
  // (fibletCullTarget reads the visible bits of this group's fiblets,
  // which only this group rewrites, after the barrier below.)
  const int target = fibletCullTarget(pc, ds, fiblet, visible);
  uint slot = 0u;
  if (target >= 0) slot = atomicAdd(s_count[target], 1u);
  if (visible) atomicOr(s_visible[local >> 5u], 1u << (local & 31u));
  barrier();
  if (local < 2u && s_count[local] > 0u) {
    FibletListRef list = FibletListRef(local == 0u ? pc.list : pc.lod_list);
    s_base[local] = atomicAdd(list.header.count, s_count[local]);
  }
  // The bit words are read above (by this group only) before they are
  // rewritten here, after the barrier.
  if (pc.mode == kCullPhase2 && local < 2u && group * 2u + local < (ds.fiblet_count + 31u) / 32u)
    bits.words[group * 2u + local] = s_visible[local];
  barrier();
  if (target >= 0) {
    FibletListRef list = FibletListRef(target == 0 ? pc.list : pc.lod_list);
    list.fiblets[s_base[target] + slot] = fiblet;
  }
}
