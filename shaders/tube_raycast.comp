// Spline tubes, compute ray casting, pass 2 (shared/tubes.h
// TubeRaycastPush): one workgroup per screen tile, one invocation per
// pixel. The tile's sub-segments (its list from the binning passes, or
// every sub-segment where the list ended past the buffer) are loaded a
// workgroup's worth at a time into shared memory as quadratics with their
// boxes; each pixel's eye ray is tested against the boxes and then
// intersected (glsl/tube_intersect.glsl), the nearest front hit kept against the
// surface texel's depth and written (glsl/tube_texel.glsl, shared with the
// fragment-shader variant's resolve).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tubes.h"
#include "shared/workgroup.h"
#include "glsl/shade_common.glsl"
#include "glsl/tangent.glsl"
#include "glsl/tube_intersect.glsl"
#include "glsl/tube_texel.glsl"
#include "glsl/surface_cuts.glsl"

// kTubeTileSize x kTubeTileSize
layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;

layout(push_constant, std430) uniform Push { TubeRaycastPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer CountsRef { uint counts[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer EndsRef { uint ends[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer ListsRef { uint items[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SurfaceRef { SurfaceTexel texels[]; };

const uint kBatch = kTubeTileSize * kTubeTileSize;
shared TubeQuadratic s_quads[kBatch];
shared vec3 s_lo[kBatch];
shared vec3 s_hi[kBatch];
shared uint s_items[kBatch];

void main() {
  const uvec2 tile = gl_WorkGroupID.xy;
  const uvec2 p = tile * kTubeTileSize + gl_LocalInvocationID.xy;
  const uint local = gl_LocalInvocationIndex;
  const bool inside = p.x < pc.width && p.y < pc.height;
  const uint index = p.y * pc.width + p.x;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  const vec3 o = cam.eye.xyz;
  const vec3 d = -pixelToEye(cam, uvec2(min(p.x, pc.width - 1u), min(p.y, pc.height - 1u)));
  const vec3 inv_d = 1.0 / mix(d, vec3(1e-30), equal(d, vec3(0.0)));
  float best_depth = inside ? SurfaceRef(pc.surface).texels[index].depth : 0.0;
  uint best_item = 0xFFFFFFFFu;
  float best_t = 0.0, best_s = 0.0;

  const uint tile_index = tile.y * pc.tiles_x + tile.x;
  const uint count = CountsRef(pc.tile_counts).counts[tile_index];
  const uint end = EndsRef(pc.tile_ends).ends[tile_index];
  const bool overflow = count > 0u && end > pc.list_capacity;
  const uint total = overflow ? pc.sub_segments : count, start = end - count;
  for (uint base = 0u; base < total; base += kBatch) {
    barrier();
    const uint k = base + local;
    if (k < total) {
      const uint item = overflow ? k : ListsRef(pc.tile_lists).items[start + k];
      const TubeSegment s = SegmentsRef(pc.segments).segments[item / 2u];
      const TubeQuadratic q =
          tubeQuadratic(NodesRef(pc.nodes).nodes[s.node], NodesRef(pc.nodes).nodes[s.node + 1u], s.chord, item % 2u);
      vec3 lo, hi;
      tubeBox(q, lo, hi);
      s_quads[local] = q;
      s_lo[local] = lo;
      s_hi[local] = hi;
      s_items[local] = item;
    }
    barrier();
    if (!inside) continue;
    const uint n = min(kBatch, total - base);
    for (uint j = 0u; j < n; ++j) {
      float enter;
      if (!tubeRayEntersBox(s_lo[j], s_hi[j], o, inv_d, enter)) continue;
      // A box the ray enters behind the nearest surface so far (a tube hit
      // or what other stages left) holds no nearer hit: skip its
      // intersection, the cost of a pixel. The margin (16 ulps of depth 1)
      // keeps every candidate that float rounding could still let win.
      const vec4 ce = cameraTransformPoint(cam.view_projection, o + enter * d);
      if (ce.w > 0.0 && ce.z / ce.w > best_depth + 1e-6) continue;
      float s, t;
      if (!tubeIntersect(s_quads[j], o, d, s, t)) continue;
      const vec4 c = cameraTransformPoint(cam.view_projection, o + s * d);
      if (!(c.w > 0.0)) continue;
      const float depth = c.z / c.w;
      // Strictly nearer than what other surfaces left; ties between tube
      // items: the smaller item (the CPU reference's order).
      if (depth >= 0.0 && depth <= 1.0 &&
          (depth < best_depth || (best_item != 0xFFFFFFFFu && depth == best_depth && s_items[j] < best_item)) &&
          surfaceCutsKeep(cam, o + s * d, index, depth)) {
        best_depth = depth;
        best_item = s_items[j];
        best_t = t;
        best_s = s;
      }
    }
  }
  if (!inside || best_item == 0xFFFFFFFFu) return;
  const TubeSegment s = SegmentsRef(pc.segments).segments[best_item / 2u];
  const TubeNode a = NodesRef(pc.nodes).nodes[s.node], b = NodesRef(pc.nodes).nodes[s.node + 1u];
  SurfaceRef(pc.surface).texels[index] = tubeSurfaceTexel(s, a, b, best_item, o + best_s * d, best_t, best_depth);
}
