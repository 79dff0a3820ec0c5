// Mesh cut, depths (shared/cut_mesh.h): one invocation per triangle of a
// closed mesh rasterises it at pixel centres into the front (facing the
// eye) or the back depth words, nearest wins (atomicMin on float bits).
// A compute raster, not the graphics pipeline: the compute pipeline runs
// on compute-only devices too. Triangles are clipped at the near plane in
// clip space first (the eye may sit inside the mesh); the pixel test is
// inclusive on every edge, so the triangles of a closed mesh leave no
// pixel of its silhouette uncovered.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kCutRasterGroupSize

layout(push_constant, std430) uniform Push { CutMeshRasterPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer PositionsRef { float xyz[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer DepthWordsRef { uint words[]; };

vec3 vertexAt(uint i) {
  PositionsRef p = PositionsRef(pc.positions);
  return vec3(p.xyz[3u * i], p.xyz[3u * i + 1u], p.xyz[3u * i + 2u]);
}

// Window x, y and depth of a clip-space point (w > 0).
vec3 toWindow(CameraBlock cam, vec4 c) { return vec3((c.xy / c.w + 1.0) * 0.5 * cam.viewport.xy, c.z / c.w); }

float edge(vec2 a, vec2 b, vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

void rasterTriangle(CameraBlock cam, vec3 a, vec3 b, vec3 c, DepthWordsRef target) {
  const float area = edge(a.xy, b.xy, c.xy);
  if (area == 0.0 || isnan(area)) return;
  const uint width = uint(cam.viewport.x), height = uint(cam.viewport.y);
  const vec2 lo = max(ceil(min(min(a.xy, b.xy), c.xy) - 0.5), vec2(0.0));
  const vec2 hi = min(floor(max(max(a.xy, b.xy), c.xy) - 0.5), cam.viewport.xy - 1.0);
  for (float y = lo.y; y <= hi.y; y += 1.0)
    for (float x = lo.x; x <= hi.x; x += 1.0) {
      const vec2 p = vec2(x + 0.5, y + 0.5);
      // Barycentrics with the sign of the area: all >= 0 inside (edges included).
      const float w0 = edge(b.xy, c.xy, p) / area, w1 = edge(c.xy, a.xy, p) / area, w2 = edge(a.xy, b.xy, p) / area;
      if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
      // z/w is affine in window coordinates over a projected triangle.
      const float z = w0 * a.z + w1 * b.z + w2 * c.z;
      if (!(z <= 1.0)) continue;
      atomicMin(target.words[uint(y) * width + uint(x)], floatBitsToUint(max(z, 0.0)));
    }
}

void main() {
  const uint t = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
                 gl_LocalInvocationIndex;
  if (t >= pc.triangle_count) return;
  const CameraBlock cam = CameraRef(pc.camera).camera;
  UintsRef tris = UintsRef(pc.triangles);
  const vec3 pa = vertexAt(tris.values[3u * t]), pb = vertexAt(tris.values[3u * t + 1u]),
             pc3 = vertexAt(tris.values[3u * t + 2u]);
  // Facing from the world: the outward normal against the direction to the eye.
  const vec3 n = cross(pb - pa, pc3 - pa);
  const bool front = dot(n, cam.eye.xyz - pa) > 0.0;
  DepthWordsRef target = DepthWordsRef(front ? pc.front : pc.back);
  vec4 c[3] = vec4[3](cameraTransformPoint(cam.view_projection, pa), cameraTransformPoint(cam.view_projection, pb),
                      cameraTransformPoint(cam.view_projection, pc3));
  // Near-plane clipping (z_clip >= 0): the kept part is a triangle or a
  // quadrilateral (two triangles).
  vec4 poly[4];
  uint n_out = 0u;
  for (uint i = 0u; i < 3u; ++i) {
    const vec4 p = c[i], q = c[(i + 1u) % 3u];
    if (p.z >= 0.0) poly[n_out++] = p;
    if ((p.z >= 0.0) != (q.z >= 0.0)) {
      vec4 cut = p + (p.z / (p.z - q.z)) * (q - p);
      cut.z = 0.0;
      poly[n_out++] = cut;
    }
  }
  if (n_out < 3u) return;
  for (uint i = 0u; i < n_out; ++i)
    if (!(poly[i].w > 0.0)) return;  // (cannot happen with z >= 0 in front of a perspective eye)
  const vec3 w0 = toWindow(cam, poly[0]);
  rasterTriangle(cam, w0, toWindow(cam, poly[1]), toWindow(cam, poly[2]), target);
  if (n_out == 4u) rasterTriangle(cam, w0, toWindow(cam, poly[2]), toWindow(cam, poly[3]), target);
}
