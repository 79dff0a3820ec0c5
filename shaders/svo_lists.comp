// SVO decoration lists (shared/svo_build.h SvoListsPush; issue 16 item 2:
// every segment that touches a leaf): one workgroup per segment walks the
// voxels of its box, as svo_voxelize.comp does, and where its own |f_s| <
// band finds the voxel among the sorted leaf codes (a voxel deep inside
// another tube is no leaf); phase 0 counts the leaf's segments, phase 1
// writes the segment into the leaf's list.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/svo.h"
#include "shared/svo_build.h"
#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/svo_capsule.glsl"
#include "glsl/svo_curve.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kSvoListsGroupSize
// Curved tubes (SvoGrid::curved) as a specialisation, so the straight
// variant carries none of the curved distance's code.
layout(constant_id = 0) const bool kCurved = false;

layout(push_constant, std430) uniform Push { SvoListsPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer CodesRef { uint codes[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer WordsRef { uint words[]; };

// The first index in [lo, hi) whose code is not below `code`.
uint lowerBound(uint code, uint lo, uint hi) {
  while (lo < hi) {
    const uint mid = (lo + hi) >> 1u;
    if (CodesRef(pc.codes).codes[mid] < code) lo = mid + 1u;
    else hi = mid;
  }
  return lo;
}

// The codes of the segment's box: Morton codes grow with each coordinate,
// so every voxel of the box has a code in [code(lo), code(hi)], a run of
// the sorted leaves found once per workgroup; each voxel then searches
// that run, not all the leaves.
shared uint s_first, s_end;

void main() {
  const uint g = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (g >= pc.segment_count) return;
  const uint seg = pc.segment_first + g;
  const TubeSegment s = SegmentsRef(pc.segments).segments[seg];
  const TubeNode na = NodesRef(pc.nodes).nodes[s.node], nb = NodesRef(pc.nodes).nodes[s.node + 1u];
  const SvoCapsuleF c = svoCapsuleOf(na, nb);
  const SvoCurveF cv = svoCurveOf(na, nb, s.chord);
  const vec3 origin = vec3(pc.origin_x, pc.origin_y, pc.origin_z);
  const float pad = c.r + pc.band;
  vec3 bmin = min(c.a, c.b), bmax = max(c.a, c.b);
  if (kCurved) svoCurveBounds(cv, bmin, bmax);
  bmin -= pad;
  bmax += pad;
  const int side = int(pc.side);
  const ivec3 lo = max(ivec3(0), ivec3(floor((bmin - origin) / pc.voxel - 0.5)));
  const ivec3 hi = min(ivec3(side - 1), ivec3(ceil((bmax - origin) / pc.voxel - 0.5)));
  if (any(greaterThan(lo, hi))) return;  // the whole workgroup: one segment
  if (gl_LocalInvocationID.x == 0u) {
    s_first = lowerBound(svoMorton(uint(lo.x), uint(lo.y), uint(lo.z)), 0u, pc.leaf_count);
    s_end = lowerBound(svoMorton(uint(hi.x), uint(hi.y), uint(hi.z)) + 1u, s_first, pc.leaf_count);
  }
  barrier();
  const uint first = s_first, end = s_end;
  const uvec3 n = uvec3(hi - lo + 1);
  const uint total = n.x * n.y * n.z;
  for (uint k = gl_LocalInvocationID.x; k < total; k += gl_WorkGroupSize.x) {
    const uvec3 v = uvec3(lo) + uvec3(k % n.x, (k / n.x) % n.y, k / (n.x * n.y));
    const vec3 p = origin + (vec3(v) + 0.5) * pc.voxel;
    float u;
    const float f = kCurved ? svoCurveDistance(cv, p, u) : svoCapsuleDistance(c, p);
    if (!(abs(f) < pc.band)) continue;
    const uint code = svoMorton(v.x, v.y, v.z);
    const uint leaf = lowerBound(code, first, end);
    if (leaf == end || CodesRef(pc.codes).codes[leaf] != code) continue;  // inside another tube: no leaf
    if (pc.phase == 0u) {
      atomicAdd(WordsRef(pc.offsets).words[leaf], 1u);
      continue;
    }
    const uint at = WordsRef(pc.offsets).words[leaf];
    const uint length = WordsRef(pc.offsets).words[leaf + 1u] - at - 1u;
    const uint slot = atomicAdd(WordsRef(pc.cursor).words[leaf], 1u);
    if (slot < length) WordsRef(pc.decoration).words[at + 1u + slot] = seg;
  }
}
