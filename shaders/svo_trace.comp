// SVO ray tracing of straight streamtubes (shared/svo.h SvoTracePush;
// seed 3.4 and Algorithm 1): one invocation per pixel. The eye ray walks
// the octree by push-down kd-restart adapted to octrees: from the restart
// node, descend to the node holding the ray's current point (the octant
// from the point's integer voxel coordinates), and at an empty node or a
// leaf without a hit move t past the node's exit and restart. While
// descending, a child that holds the whole rest of the ray inside the root
// (its exit at or past the ray's exit) becomes the restart node, so later
// restarts skip the levels above it (the push-down). No stack.
//
// In a leaf: every capsule of its decoration list, exactly
// (glsl/svo_capsule.glsl), the nearest hit whose t lies in the leaf's
// stretch of the ray [t_enter, t_exit] (a little slack for the boundary)
// ends the walk. A hit past the leaf's exit is not taken there: a nearer
// surface may lie in the leaves between, and the hit's own leaf lists its
// capsule (shared/svo.h's band rule).
//
// Curved (pc.curved, svo-curved): in a leaf, sphere tracing of the union
// (min) of its list's curved-tube distances (glsl/svo_curve.glsl) from the
// leaf's entry less the slack, at most kSvoSphereSteps steps, a hit where
// the union falls below kSvoHitEpsilon * voxel before the leaf's exit plus
// the slack (steps spent before it: the walk resumes there). The union of the list bounds the distance to the list's
// surfaces from below (each distance is exact), so no step crosses one;
// surfaces of segments not in the list do not enter the leaf. Normal: the
// distance's gradient, p - C(u*) at the nearest point u*.
//
// Level of detail (pc.lod_px > 0; shared/svo.h states the error): an
// internal node below lod_px pixel footprints at the ray's current point t0
// is not descended; its representative segment (pc.svo_lod) stands in for
// the subtree. The hit: the ray's front hit on the representative's
// capsule (its chord's, curved too) where that lies in the node's stretch
// [t0, t_exit], else the ray's closest approach to its axis, clamped to
// that stretch. Not the box's entry: a node holding one tube then shows
// that tube's true depth and silhouette shading rather than a cube's face,
// and the clamp keeps every hit in the box, so the bound (the box's
// diagonal) holds whatever the representative. Normal from its axis to
// the hit point; fiber and position along it (curved: at the curve's
// nearest point) from it.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"
#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/shade_common.glsl"
#include "glsl/tangent.glsl"
#include "glsl/svo_capsule.glsl"
#include "glsl/svo_curve.glsl"
#include "glsl/surface_cuts.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kSvoTraceTile^2

layout(push_constant, std430) uniform Push { SvoTracePush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer SvoNodesRef { SvoNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer DecorationRef { uint words[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SurfaceRef { SurfaceTexel texels[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer LodRef { uint segments[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer StatsRef { uint counts[]; };

// Where the ray leaves the box [lo, hi].
float boxExit(vec3 lo, vec3 hi, vec3 o, vec3 inv_d) {
  const vec3 a = (lo - o) * inv_d, b = (hi - o) * inv_d;
  const vec3 far_t = max(a, b);
  return min(far_t.x, min(far_t.y, far_t.z));
}

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint index = p.y * pc.width + p.x;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  const vec3 o = cam.eye.xyz;
  const vec3 d = -pixelToEye(cam, p);
  const vec3 inv_d = 1.0 / mix(d, vec3(1e-30), equal(d, vec3(0.0)));
  const vec3 origin = vec3(pc.origin_x, pc.origin_y, pc.origin_z);
  const uint side = 1u << pc.levels;
  const float voxel = pc.voxel;

  // The ray inside the root's box.
  const vec3 root_hi = origin + float(side) * voxel;
  const vec3 ta = (origin - o) * inv_d, tb = (root_hi - o) * inv_d;
  const vec3 tn = min(ta, tb), tf = max(ta, tb);
  float t0 = max(max(tn.x, max(tn.y, tn.z)), 0.0);
  float t1 = min(tf.x, min(tf.y, tf.z));
  // The frame's clip planes (the user's and the slab's) cut the ray to the
  // stretch they all keep, so the walk finds the first tube on the kept
  // side: tubes are clipped, not dropped (a tube cut by a plane shows its
  // surface up to it, open), and those behind a cut one still show.
  const uint planes = min(uint(cam.cuts.x), kMaxFrameClipPlanes);
  for (uint i = 0u; i < planes; ++i) {
    const float nd = dot(cam.clip_world[i].xyz, d), f0 = dot(cam.clip_world[i].xyz, o) + cam.clip_world[i].w;
    if (nd > 0.0) t0 = max(t0, -f0 / nd);
    else if (nd < 0.0) t1 = min(t1, -f0 / nd);
    else if (f0 < 0.0) return;
  }
  if (!(t0 < t1)) return;

  // nudge: t past a cell's entry for its lookup (well above a float ulp of
  // the point); slack: how far outside the leaf's stretch a hit is still
  // taken there (at least the nudge, so corners skipped by it still count).
  const float nudge = 1e-3 * voxel, slack = 2e-3 * voxel;
  uint restart_node = 0u, restart_level = 0u;
  uvec3 restart_cell = uvec3(0u);
  uint best_seg = 0xFFFFFFFFu;
  float best_t = 0.0, best_u = 0.0;
  const bool curved = pc.curved != 0u;
  const float hit_eps = kSvoHitEpsilon * voxel;
  // A bound on the walk (a ray crosses at most 3 * side leaves; each walk
  // step is one restart).
  const uint max_steps = 3u * side + 64u;
  const bool lod = pc.lod_px > 0.0;
  const float lod_scale = pc.lod_px * pc.pixel_angle;
  bool lod_hit = false;
  uint visits = 0u, tests = 0u;  // pc.stats
  for (uint step = 0u; step < max_steps && t0 < t1 && best_seg == 0xFFFFFFFFu; ++step) {
    const vec3 g = (o + d * (t0 + nudge) - origin) / voxel;
    const uvec3 gi = uvec3(clamp(ivec3(floor(g)), ivec3(0), ivec3(int(side) - 1)));
    uint node = restart_node, level = restart_level;
    uvec3 cell = restart_cell;
    bool push = true;
    for (;;) {
      const uint size = side >> level;
      const vec3 lo = origin + vec3(cell) * voxel, hi = lo + float(size) * voxel;
      const float t_exit = boxExit(lo, hi, o, inv_d);
      const uint ref = SvoNodesRef(pc.svo_nodes).nodes[node].ref;
      const uint type = ref & kSvoNodeTypeMask;
      ++visits;
      if (type == kSvoNodeInternal && lod && float(size) * voxel < lod_scale * t0) {
        const uint seg = LodRef(pc.svo_lod).segments[((ref & kSvoNodeIndexMask) - 1u) >> 3u];
        const TubeSegment s = SegmentsRef(pc.segments).segments[seg];
        const TubeNode na = NodesRef(pc.nodes).nodes[s.node], nb = NodesRef(pc.nodes).nodes[s.node + 1u];
        const SvoCapsuleF c = svoCapsuleOf(na, nb);
        float t;
        if (!svoIntersectCapsule(c, o, d, 0.0, t) || t > t_exit) t = svoRayClosestApproach(c, o, d);
        best_t = clamp(t, t0, t_exit);
        best_seg = seg;
        lod_hit = true;
        ++tests;
        if (curved) svoCurveDistance(svoCurveOf(na, nb, s.chord), o + best_t * d, best_u);
        break;
      }
      if (type == kSvoNodeInternal) {
        const uint half_size = size >> 1u;
        const uvec3 bits = uvec3(greaterThanEqual(gi - cell, uvec3(half_size)));
        const uint child = (ref & kSvoNodeIndexMask) + (bits.x | (bits.y << 1u) | (bits.z << 2u));
        const uvec3 child_cell = cell + bits * half_size;
        if (push) {
          const vec3 clo = origin + vec3(child_cell) * voxel;
          if (boxExit(clo, clo + float(half_size) * voxel, o, inv_d) >= t1) {
            restart_node = child;
            restart_level = level + 1u;
            restart_cell = child_cell;
          } else {
            push = false;
          }
        }
        node = child;
        level += 1u;
        cell = child_cell;
        continue;
      }
      if (type == kSvoNodeLeaf) {
        const uint list = ref & kSvoNodeIndexMask;
        const uint count = DecorationRef(pc.decoration).words[list];
        if (curved) {
          float t = max(t0 - slack, 0.0);
          const float t_end = t_exit + slack;
          for (uint it = 0u; it < kSvoSphereSteps && t <= t_end; ++it) {
            const vec3 q = o + t * d;
            float f = 1e30, fu = 0.0;
            uint fs = 0xFFFFFFFFu;
            tests += count;
            for (uint k = 0u; k < count; ++k) {
              const uint seg = DecorationRef(pc.decoration).words[list + 1u + k];
              const TubeSegment s = SegmentsRef(pc.segments).segments[seg];
              float u;
              const float fk = svoCurveDistance(
                  svoCurveOf(NodesRef(pc.nodes).nodes[s.node], NodesRef(pc.nodes).nodes[s.node + 1u], s.chord), q, u);
              if (fk < f || (fk == f && seg < fs)) {
                f = fk;
                fu = u;
                fs = seg;
              }
            }
            if (f < hit_eps) {
              best_seg = fs;
              best_t = t;
              best_u = fu;
              break;
            }
            t += f;
          }
          // Steps spent before the leaf's end (a ray grazing a tube): the
          // next walk step resumes from t in this leaf rather than skipping
          // the untraced rest of it (which could pass through a surface).
          t0 = best_seg == 0xFFFFFFFFu && t <= t_end ? max(t, t0 + nudge) : max(t_exit, t0 + nudge);
          break;
        }
        float leaf_best = t_exit + slack;
        tests += count;
        for (uint k = 0u; k < count; ++k) {
          const uint seg = DecorationRef(pc.decoration).words[list + 1u + k];
          const TubeSegment s = SegmentsRef(pc.segments).segments[seg];
          const SvoCapsuleF c =
              svoCapsuleOf(NodesRef(pc.nodes).nodes[s.node], NodesRef(pc.nodes).nodes[s.node + 1u]);
          float t;
          if (!svoIntersectCapsule(c, o, d, 0.0, t)) continue;
          if (t < t0 - slack || t > leaf_best || (t == leaf_best && seg > best_seg)) continue;
          leaf_best = t;
          best_seg = seg;
        }
        if (best_seg != 0xFFFFFFFFu) best_t = leaf_best;
      }
      t0 = max(t_exit, t0 + nudge);
      break;
    }
  }
  if (pc.stats != 0ul) {
    atomicAdd(StatsRef(pc.stats).counts[0], visits);
    atomicAdd(StatsRef(pc.stats).counts[1], tests);
  }
  if (best_seg == 0xFFFFFFFFu) return;

  const vec3 hit = o + best_t * d;
  const vec4 clip = cameraTransformPoint(cam.view_projection, hit);
  if (!(clip.w > 0.0)) return;
  const float depth = clip.z / clip.w;
  if (depth < 0.0 || depth > 1.0 || !(depth < SurfaceRef(pc.surface).texels[index].depth)) return;
  if (!surfaceCutsKeep(cam, hit, index, depth)) return;  // a mesh cut (or a hit within the slack before a plane)
  const TubeSegment s = SegmentsRef(pc.segments).segments[best_seg];
  const TubeNode na = NodesRef(pc.nodes).nodes[s.node], nb = NodesRef(pc.nodes).nodes[s.node + 1u];
  if (curved) {
    const SvoCurveF cv = svoCurveOf(na, nb, s.chord);
    const vec3 centre = svoCurvePoint(cv, best_u), along = svoCurveDerivative(cv, best_u);
    SurfaceTexel texel;
    texel.depth = depth;
    texel.fiber = s.fiber;
    // A level-of-detail hit may lie on the centre line: facing the eye then.
    texel.normal = packSegmentTangent(lod_hit && hit == centre ? -d : hit - centre);
    texel.tangent = dot(along, along) > 0.0 ? packSegmentTangent(along) : texel.normal;
    texel.position = mix(na.point, nb.point, best_u);
    texel.color = 0u;
    texel.source = kSurfaceSourceSvo;
    texel.pad0 = 0u;
    SurfaceRef(pc.surface).texels[index] = texel;
    return;
  }
  const SvoCapsuleF c = svoCapsuleOf(na, nb);
  const vec3 ba = c.b - c.a;
  const float baba = dot(ba, ba);
  const float u = baba > 0.0 ? clamp(dot(hit - c.a, ba) / baba, 0.0, 1.0) : 0.0;
  SurfaceTexel texel;
  texel.depth = depth;
  texel.fiber = s.fiber;
  texel.normal = packSegmentTangent(lod_hit && hit == c.a + u * ba ? -d : hit - (c.a + u * ba));
  // A sphere (zero-length segment) has no direction: its normal, as the
  // spline tubes do.
  texel.tangent = baba > 0.0 ? packSegmentTangent(ba) : texel.normal;
  texel.position = mix(na.point, nb.point, u);
  texel.color = 0u;
  texel.source = kSurfaceSourceSvo;
  texel.pad0 = 0u;
  SurfaceRef(pc.surface).texels[index] = texel;
}
