// Spline tubes by adaptive tessellation, control stage (shared/tube_tess.h;
// seed section 3.1, figure 8): one patch of one control point per base-mesh
// quad. Culls the caps between joined segments and, with culling on, a
// patch whose corners all face away from the eye or that lies outside the
// frustum; sets each
// outer level from its edge alone (canonical corner order, so neighbours
// agree: no cracks) by the screen-space edge-length criterion and, on ring
// edges the silhouette crosses, the silhouette criterion; inner levels are
// the larger of the two opposite outer ones.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/tube_tess.h"
#include "shared/tubes.h"
#define SHADE_COMMON_NO_TILES  // graphics stage: no workgroup built-ins
#include "glsl/shade_common.glsl"
#include "glsl/tube_tess.glsl"

layout(vertices = 1) out;

layout(push_constant, std430) uniform Push { TubeTessPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer NodesRef { TubeNode nodes[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer SegmentsRef { TubeSegment segments[]; };

layout(location = 0) in uint in_patch[];
layout(location = 0) patch out uint patch_index;

CameraBlock cam;
float pixels_per_unit;  // viewport pixels per world mm at clip w = 1

float clipW(vec3 p) { return cameraTransformPoint(cam.view_projection, p).w; }

// Edge-length criterion: world length / w x the viewport's pixels per
// unit, in pieces of kTubeTessEdgePx. An end near or behind the eye takes
// the clamp (the rasteriser clips the rest).
float edgeLevel(vec3 p0, vec3 p1, float world_length) {
  const float w = min(clipW(p0), clipW(p1));
  if (!(w > 0.5 * cam.depth_range.x)) return kTubeTessEdgeClamp;
  return clamp(ceil(world_length / w * pixels_per_unit / kTubeTessEdgePx), 1.0, kTubeTessEdgeClamp);
}

// Silhouette criterion on an arc of `span` radians and radius r from p0
// (normal n0) to p1 (n1): where the silhouette crosses it (the normals'
// sides of the eye differ, or one is within a quarter of the span of
// grazing), the pieces L with r (1 - cos(span / 2L)) <= the tolerance.
float silhouetteLevel(vec3 p0, vec3 n0, vec3 p1, vec3 n1, float r, float span) {
  const vec3 e = cam.eye.xyz;
  const float c0 = dot(n0, normalize(e - p0)), c1 = dot(n1, normalize(e - p1));
  if (c0 * c1 > 0.0 && min(abs(c0), abs(c1)) > 0.25 * span) return 1.0;
  const float w = min(clipW(p0), clipW(p1));
  if (!(w > 0.5 * cam.depth_range.x)) return kTubeTessSilhouetteClamp;
  const float tolerance = kTubeTessSilhouettePx * w / pixels_per_unit;  // world mm
  if (!(r > tolerance)) return 1.0;
  const float half_piece = acos(1.0 - tolerance / r);
  return clamp(ceil(0.5 * span / half_piece), 1.0, kTubeTessSilhouetteClamp);
}

// The ring edge at u from corner k to k + 1 around (the body's rows and
// the caps' seams alike).
float ringEdgeLevel(TubeTessSegment g, float u, uint k) {
  vec3 n0, n1;
  const vec3 p0 = tubeTessBodyPoint(g, u, tubeTessAround(k, pc.vertices), n0);
  const vec3 p1 = tubeTessBodyPoint(g, u, tubeTessAround(k + 1u, pc.vertices), n1);
  const float span = 2.0 * kTubeTessPi / float(pc.vertices);
  return max(edgeLevel(p0, p1, distance(p0, p1)), silhouetteLevel(p0, n0, p1, n1, tubeTessRadius(g, u), span));
}

// The sphere (c, radius) wholly outside one of the frustum's planes: the
// rows of view_projection give them (Gribb and Hartmann), in Vulkan's clip
// depth [0, w].
bool outsideFrustum(vec3 c, float radius) {
  const vec4 m0 = cam.view_projection[0], m1 = cam.view_projection[1], m2 = cam.view_projection[2],
             m3 = cam.view_projection[3];
  const vec4 rx = vec4(m0.x, m1.x, m2.x, m3.x), ry = vec4(m0.y, m1.y, m2.y, m3.y);
  const vec4 rz = vec4(m0.z, m1.z, m2.z, m3.z), rw = vec4(m0.w, m1.w, m2.w, m3.w);
  const vec4 planes[6] = vec4[6](rw + rx, rw - rx, rw + ry, rw - ry, rz, rw - rz);
  for (int i = 0; i < 6; ++i)
    if (dot(planes[i].xyz, c) + planes[i].w < -radius * length(planes[i].xyz)) return true;
  return false;
}

// Frustum test of a patch with these corners on a tube of radius r.
bool patchOutside(vec3 p0, vec3 p1, vec3 p2, vec3 p3, float r) {
  if ((pc.flags & kTubeTessFlagFrustumCulling) == 0u) return false;
  const vec3 c = 0.25 * (p0 + p1 + p2 + p3);
  const float reach = max(max(distance(c, p0), distance(c, p1)), max(distance(c, p2), distance(c, p3)));
  return outsideFrustum(c, reach * (1.0 + kTubeTessBulge) + kTubeTessBulge * r);
}

bool facesAway(vec3 p, vec3 n) { return dot(n, normalize(cam.eye.xyz - p)) < -kTubeTessBackMargin; }

void cull() {
  gl_TessLevelOuter[0] = gl_TessLevelOuter[1] = gl_TessLevelOuter[2] = gl_TessLevelOuter[3] = 0.0;
  gl_TessLevelInner[0] = gl_TessLevelInner[1] = 0.0;
}

void main() {
  const uint g_index = in_patch[0];
  patch_index = g_index;
  const uint per_segment = tubeTessPatchesPerSegment(pc.rings, pc.vertices);
  const uint si = g_index / per_segment, local = g_index % per_segment;
  const uint row = local / pc.vertices, k = local % pc.vertices;
  if (si >= pc.segment_count) {
    cull();
    return;
  }
  cam = CameraRef(pc.camera).camera;
  pixels_per_unit = 0.5 * max(length(vec3(cam.view_projection[0].x, cam.view_projection[1].x,
                                          cam.view_projection[2].x)) * cam.viewport.x,
                              length(vec3(cam.view_projection[0].y, cam.view_projection[1].y,
                                          cam.view_projection[2].y)) * cam.viewport.y);
  SegmentsRef segs = SegmentsRef(pc.segments);
  const TubeSegment s = segs.segments[si];
  const TubeTessSegment g = tubeTessSegment(s, NodesRef(pc.nodes).nodes[s.node], NodesRef(pc.nodes).nodes[s.node + 1u]);
  const bool back_culling = (pc.flags & kTubeTessFlagBackCulling) != 0u;
  const float a0 = tubeTessAround(k, pc.vertices), a1 = tubeTessAround(k + 1u, pc.vertices);
  float outer0, outer1, outer2, outer3;  // edges x = 0, y = 0, x = 1, y = 1
  if (row < pc.rings) {
    const float u0 = float(row) / float(pc.rings), u1 = float(row + 1u) / float(pc.rings);
    vec3 n00, n10, n01, n11;  // corner (around, along)
    const vec3 p00 = tubeTessBodyPoint(g, u0, a0, n00), p10 = tubeTessBodyPoint(g, u0, a1, n10);
    const vec3 p01 = tubeTessBodyPoint(g, u1, a0, n01), p11 = tubeTessBodyPoint(g, u1, a1, n11);
    if ((back_culling && facesAway(p00, n00) && facesAway(p10, n10) && facesAway(p01, n01) && facesAway(p11, n11)) ||
        patchOutside(p00, p10, p01, p11, max(tubeTessRadius(g, u0), tubeTessRadius(g, u1)))) {
      cull();
      return;
    }
    outer0 = edgeLevel(p00, p01, distance(p00, p01));
    outer2 = edgeLevel(p10, p11, distance(p10, p11));
    outer1 = ringEdgeLevel(g, u0, k);
    outer3 = ringEdgeLevel(g, u1, k);
  } else {
    // A cap: only where the segment begins (ends) its tube.
    const bool start = row == pc.rings;
    const bool joined = start ? si > 0u && segs.segments[si - 1u].node + 1u == s.node
                              : si + 1u < pc.segment_count && segs.segments[si + 1u].node == s.node + 1u;
    if (joined) {
      cull();
      return;
    }
    const float cap = start ? -1.0 : 1.0, u = start ? 0.0 : 1.0;
    vec3 n0, n1, np;
    const vec3 p0 = tubeTessBodyPoint(g, u, a0, n0), p1 = tubeTessBodyPoint(g, u, a1, n1);
    const vec3 pole = tubeTessCapPoint(g, cap, a0, 1.0, np);
    if ((back_culling && facesAway(p0, n0) && facesAway(p1, n1) && facesAway(pole, np)) ||
        patchOutside(p0, p1, pole, pole, tubeTessRadius(g, u))) {
      cull();
      return;
    }
    // Meridians: a quarter arc from the seam to the pole, in at least
    // vertices / 2 pieces (the finer seam: the cap's triangles, 2 pi /
    // vertices wide at the seam, are half as tall, so their circumradius
    // on the sphere, half the diagonal, stays near the body's facets' and
    // the cap as close to its sphere), refined as the body's edges.
    const float r = tubeTessRadius(g, u), quarter = 0.5 * kTubeTessPi;
    const float base = ceil(float(pc.vertices) / 2.0);
    outer0 = max(base, max(edgeLevel(p0, pole, quarter * r), silhouetteLevel(p0, n0, pole, np, r, quarter)));
    outer2 = max(base, max(edgeLevel(p1, pole, quarter * r), silhouetteLevel(p1, n1, pole, np, r, quarter)));
    outer1 = ringEdgeLevel(g, u, k);  // the seam: the body's end ring edge
    outer3 = 1.0;                     // the pole, a point
  }
  gl_TessLevelOuter[0] = outer0;
  gl_TessLevelOuter[1] = outer1;
  gl_TessLevelOuter[2] = outer2;
  gl_TessLevelOuter[3] = outer3;
  gl_TessLevelInner[0] = max(outer1, outer3);
  gl_TessLevelInner[1] = max(outer0, outer2);
}
