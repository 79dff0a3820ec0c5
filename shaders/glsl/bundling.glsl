// Buffer-reference types and helpers of the bundling passes (GLSL only;
// the pushes come from shared/bundling.h). Requires GL_EXT_buffer_reference
// and GL_EXT_shader_explicit_arithmetic_types_int64 in the including shader.
#ifndef FIBSCOPE_GLSL_BUNDLING_GLSL
#define FIBSCOPE_GLSL_BUNDLING_GLSL

#include "shared/bundling.h"

layout(buffer_reference, std430, buffer_reference_align = 4) buffer BundleFloatsRef { float values[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer BundleUintsRef { uint values[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer BundleVec4Ref { vec4 values[]; };

// The flattened invocation index of a 2D dispatch grid (gpu::dispatchGrid).
// Include after the layout(local_size_x_id ...) declaration: before it,
// gl_WorkGroupSize is the default 1, not the specialised size.
uint bundleInvocation() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
}

uint bundleVoxelIndex(BundleGridBlock g, uint x, uint y, uint z) { return x + g.nx * (y + g.ny * z); }

// The voxel holding p, clamped into the grid.
uvec3 bundleVoxelOf(BundleGridBlock g, vec3 p) {
  const vec3 q = floor((p - vec3(g.origin_x, g.origin_y, g.origin_z)) / g.voxel);
  return uvec3(clamp(q, vec3(0.0), vec3(g.nx - 1u, g.ny - 1u, g.nz - 1u)));
}

vec3 bundlePoint(BundleFloatsRef points, uint i) {
  return vec3(points.values[3u * i], points.values[3u * i + 1u], points.values[3u * i + 2u]);
}

// The density at voxel index i: floats, or the anisotropic splat's fixed
// point (is_count: uint values times scale).
float bundleDensity(uint64_t density, uint is_count, float scale, uint i) {
  return is_count != 0u ? float(BundleUintsRef(density).values[i]) * scale : BundleFloatsRef(density).values[i];
}

// One component of the gradient at voxel `index` (coordinate `at` of n
// along the axis, `stride` apart): (D[i+1] - D[i-1]) / 2h, one-sided
// (D[i+1] - D[i]) / h at the grid's faces, 0 on a grid one voxel thick.
float bundleDifference(uint64_t density, uint is_count, float scale, float voxel, uint index, uint at, uint n,
                       uint stride) {
  if (n < 2u) return 0.0;
  const uint lo = at > 0u ? index - stride : index;
  const uint hi = at + 1u < n ? index + stride : index;
  const float span = float((at + 1u < n ? 1u : 0u) + (at > 0u ? 1u : 0u)) * voxel;
  return (bundleDensity(density, is_count, scale, hi) - bundleDensity(density, is_count, scale, lo)) / span;
}

// The density's gradient at voxel v (world units): what the gradient pass
// writes and the advection interpolates.
vec3 bundleGradientAt(BundleGridBlock g, uint64_t density, uint is_count, float scale, uvec3 v) {
  const uint index = bundleVoxelIndex(g, v.x, v.y, v.z);
  return vec3(bundleDifference(density, is_count, scale, g.voxel, index, v.x, g.nx, 1u),
              bundleDifference(density, is_count, scale, g.voxel, index, v.y, g.ny, g.nx),
              bundleDifference(density, is_count, scale, g.voxel, index, v.z, g.nz, g.nx * g.ny));
}

// The structure tensor's cell grid over voxel grid g: same origin, cells of
// `cell` voxels a side, ceil(n / cell) a side (bundleStructureGrid in C++).
BundleGridBlock bundleStructureCells(BundleGridBlock g, uint cell) {
  BundleGridBlock c = g;
  c.voxel = g.voxel * float(cell);
  c.nx = (g.nx + cell - 1u) / cell;
  c.ny = (g.ny + cell - 1u) / cell;
  c.nz = (g.nz + cell - 1u) / cell;
  return c;
}

// The largest eigenvalue of symmetric positive semi-definite j, in closed
// form (the trigonometric solution of the characteristic cubic): exact for
// a multiple eigenvalue too, where iterative methods converge slowly.
float bundleLargestEigenvalue(mat3 j) {
  const float q = (j[0][0] + j[1][1] + j[2][2]) / 3.0;
  const float off = j[1][0] * j[1][0] + j[2][0] * j[2][0] + j[2][1] * j[2][1];
  const vec3 d = vec3(j[0][0], j[1][1], j[2][2]) - q;
  const float p2 = dot(d, d) + 2.0 * off;
  if (!(p2 > 1e-12 * q * q)) return q;  // a multiple of the identity
  const float p = sqrt(p2 / 6.0);
  const float r = clamp(determinant((j - mat3(q)) / p) * 0.5, -1.0, 1.0);
  return q + 2.0 * p * cos(acos(r) / 3.0);
}

#endif
