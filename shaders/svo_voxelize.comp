// SVO voxelisation (shared/svo.h SvoVoxelizePush; seed 3.1, eq. 1): one
// workgroup per segment splats the signed distance of its capsule over
// the voxels of its box within the slab, union by atomicMin of ordered
// keys (pc.curved: the curved tube's distance by nearest point,
// glsl/svo_curve.glsl, over the box of its Bezier control points). A compute splat rather than the seed's slice-by-slice raster: no
// render targets or geometry shader, so it runs on compute-only devices and
// lavapipe, and each segment touches only its own box.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"
#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/svo_capsule.glsl"
#include "glsl/svo_curve.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kSvoVoxelizeGroupSize

layout(push_constant, std430) uniform Push { SvoVoxelizePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer FieldRef { uint keys[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ListRef { uint ids[]; };

void main() {
  const uint g = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (g >= pc.segment_count) return;
  const uint seg = pc.list != 0ul ? ListRef(pc.list).ids[g] : g;
  const TubeSegment s = SegmentsRef(pc.segments).segments[seg];
  const TubeNode na = NodesRef(pc.nodes).nodes[s.node], nb = NodesRef(pc.nodes).nodes[s.node + 1u];
  const SvoCapsuleF c = svoCapsuleOf(na, nb);
  const SvoCurveF cv = svoCurveOf(na, nb, s.chord);
  const bool curved = pc.curved != 0u;
  const vec3 origin = vec3(pc.origin_x, pc.origin_y, pc.origin_z);
  const float pad = c.r + pc.band;
  vec3 bmin = min(c.a, c.b), bmax = max(c.a, c.b);
  if (curved) svoCurveBounds(cv, bmin, bmax);
  bmin -= pad;
  bmax += pad;
  const int side = int(pc.side);
  const uint rows = pc.rows != 0u ? pc.rows : pc.side;
  ivec3 lo = max(ivec3(0), ivec3(floor((bmin - origin) / pc.voxel - 0.5)));
  // z: the slab's range below bounds it.
  ivec3 hi = min(ivec3(side - 1, int(rows) - 1, 0x7FFFFFFF), ivec3(ceil((bmax - origin) / pc.voxel - 0.5)));
  lo.z = max(lo.z, int(pc.slab_z0));
  hi.z = min(hi.z, int(pc.slab_z0 + pc.slab_depth) - 1);
  if (any(greaterThan(lo, hi))) return;
  const uvec3 n = uvec3(hi - lo + 1);
  const uint total = n.x * n.y * n.z;
  for (uint k = gl_LocalInvocationID.x; k < total; k += gl_WorkGroupSize.x) {
    const uvec3 v = uvec3(lo) + uvec3(k % n.x, (k / n.x) % n.y, k / (n.x * n.y));
    const vec3 p = origin + (vec3(v) + 0.5) * pc.voxel;
    float u;
    const float f = curved ? svoCurveDistance(cv, p, u) : svoCapsuleDistance(c, p);
    if (!(f < pc.band)) continue;
    atomicMin(FieldRef(pc.field).keys[((v.z - pc.slab_z0) * rows + v.y) * pc.side + v.x], svoOrderedKey(f));
  }
}
