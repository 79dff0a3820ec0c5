// Bundling, constrained advection (shared/bundling.h; FiberVisualizer
// section 7): one invocation per sample moves it by R h along the gradient
// projected on the plane orthogonal to the fiber,
//   u = d x (g x d) = g - d (d . g),  p += R h u / |g|,
// g the density gradient (central differences, bundleGradientAt)
// interpolated trilinearly at p (between voxel centres, clamped at the
// faces), d the unit direction of the fiber there
// (central difference of the neighbouring samples, one-sided at the ends).
// Structure-aware (pc.structure != 0): g in the numerator becomes M g,
// M = (J / lambda1)^power, J the structure tensor trilinear between cell
// centres (the identity where lambda1 <= kBundleMinGradient^2): across a
// sheet of fibers the step keeps its length, in the sheet's plane it
// shrinks by (lambda2 / lambda1)^power.
// A sample whose gradient is shorter than kBundleMinGradient, or whose
// neighbours coincide, stays; so do the end samples with anchor_ends.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
layout(local_size_x_id = WORKGROUP_SIZE_X_ID) in;  // kBundleGroupSize

#include "glsl/bundling.glsl"

layout(push_constant, std430) uniform Push { BundleSamplePush pc; };

// The gradient at voxel v from the density (6 reads), rather than from a
// stored gradient grid: 16 bytes a voxel less on the device.
vec3 gradientAt(uvec3 v) { return bundleGradientAt(pc.grid, pc.field, pc.field_is_count, pc.field_scale, v); }

vec3 trilinearGradient(vec3 p) {
  const vec3 size = vec3(pc.grid.nx, pc.grid.ny, pc.grid.nz);
  const vec3 q = (p - vec3(pc.grid.origin_x, pc.grid.origin_y, pc.grid.origin_z)) / pc.grid.voxel - 0.5;
  const vec3 i0 = clamp(floor(q), vec3(0.0), max(size - 2.0, vec3(0.0)));
  const vec3 t = clamp(q - i0, vec3(0.0), vec3(1.0));
  const uvec3 a = uvec3(i0);
  const uvec3 b = uvec3(min(i0 + 1.0, size - 1.0));
  const vec3 x00 = mix(gradientAt(uvec3(a.x, a.y, a.z)), gradientAt(uvec3(b.x, a.y, a.z)), t.x);
  const vec3 x10 = mix(gradientAt(uvec3(a.x, b.y, a.z)), gradientAt(uvec3(b.x, b.y, a.z)), t.x);
  const vec3 x01 = mix(gradientAt(uvec3(a.x, a.y, b.z)), gradientAt(uvec3(b.x, a.y, b.z)), t.x);
  const vec3 x11 = mix(gradientAt(uvec3(a.x, b.y, b.z)), gradientAt(uvec3(b.x, b.y, b.z)), t.x);
  return mix(mix(x00, x10, t.y), mix(x01, x11, t.y), t.z);
}

mat3 tensorAt(BundleGridBlock cells, uvec3 c) {
  BundleFloatsRef t = BundleFloatsRef(pc.structure);
  const uint i = 6u * bundleVoxelIndex(cells, c.x, c.y, c.z);
  const float xx = t.values[i], xy = t.values[i + 1u], xz = t.values[i + 2u];
  const float yy = t.values[i + 3u], yz = t.values[i + 4u], zz = t.values[i + 5u];
  return mat3(xx, xy, xz, xy, yy, yz, xz, yz, zz);
}

mat3 trilinearTensor(vec3 p) {
  const BundleGridBlock cells = bundleStructureCells(pc.grid, pc.structure_cell);
  const vec3 size = vec3(cells.nx, cells.ny, cells.nz);
  const vec3 q = (p - vec3(cells.origin_x, cells.origin_y, cells.origin_z)) / cells.voxel - 0.5;
  const vec3 i0 = clamp(floor(q), vec3(0.0), max(size - 2.0, vec3(0.0)));
  const vec3 t = clamp(q - i0, vec3(0.0), vec3(1.0));
  const uvec3 a = uvec3(i0);
  const uvec3 b = uvec3(min(i0 + 1.0, size - 1.0));
  const mat3 x00 = tensorAt(cells, uvec3(a.x, a.y, a.z)) * (1.0 - t.x) + tensorAt(cells, uvec3(b.x, a.y, a.z)) * t.x;
  const mat3 x10 = tensorAt(cells, uvec3(a.x, b.y, a.z)) * (1.0 - t.x) + tensorAt(cells, uvec3(b.x, b.y, a.z)) * t.x;
  const mat3 x01 = tensorAt(cells, uvec3(a.x, a.y, b.z)) * (1.0 - t.x) + tensorAt(cells, uvec3(b.x, a.y, b.z)) * t.x;
  const mat3 x11 = tensorAt(cells, uvec3(a.x, b.y, b.z)) * (1.0 - t.x) + tensorAt(cells, uvec3(b.x, b.y, b.z)) * t.x;
  const mat3 y0 = x00 * (1.0 - t.y) + x10 * t.y;
  const mat3 y1 = x01 * (1.0 - t.y) + x11 * t.y;
  return y0 * (1.0 - t.z) + y1 * t.z;
}

// M g with M = (J / lambda1)^power; g itself where J has no direction.
vec3 structureFiltered(vec3 p, vec3 g) {
  const mat3 j = trilinearTensor(p);
  const float lambda1 = bundleLargestEigenvalue(j);
  if (!(lambda1 > kBundleMinGradient * kBundleMinGradient)) return g;
  const mat3 a = j / lambda1;
  vec3 m = g;
  for (uint k = 0u; k < pc.structure_power; ++k) m = a * m;
  return m;
}

void main() {
  const uint i = bundleInvocation();
  if (i >= pc.sample_count) return;
  BundleVec4Ref src = BundleVec4Ref(pc.src);
  const vec4 p = src.values[i];
  const uint fiber = BundleUintsRef(pc.sample_fiber).values[i];
  const uint s0 = BundleUintsRef(pc.sample_offsets).values[fiber];
  const uint s1 = BundleUintsRef(pc.sample_offsets).values[fiber + 1u];
  vec4 result = p;
  const bool end = i == s0 || i + 1u == s1;
  if (!(end && pc.anchor_ends != 0u)) {
    const vec3 along = src.values[min(i + 1u, s1 - 1u)].xyz - src.values[i > s0 ? i - 1u : i].xyz;
    const vec3 g = trilinearGradient(p.xyz);
    const float glen = length(g);
    const float alen = length(along);
    if (glen > kBundleMinGradient && alen > 0.0) {
      const vec3 d = along / alen;
      const vec3 m = pc.structure != 0ul ? structureFiltered(p.xyz, g) : g;
      const vec3 u = m - d * dot(d, m);
      result = vec4(p.xyz + u * (pc.step / glen), p.w);
    }
  }
  BundleVec4Ref(pc.dst).values[i] = result;
}
