// The nearest-voxel rule of a voxel mask, shared by the CPU fiber filter
// (select/voxel_mask.h) and the GPU kept-bit pass: MRtrix3 tckedit's
// ROI::contains for an image region, bit for bit.
//
// World -> voxel is a float 3x4 matrix given as three rows (xyz: the linear
// part, w: the translation). The voxel coordinate of point p along a row is
//     c = (row.x * p.x + row.y * p.y) + (row.z * p.z + row.w)
// in float, every product and sum rounded on its own (no FMA: `precise` in
// GLSL, -ffp-contract=off in C++). That is the order in which tckedit's
// Eigen sums its 3x4 float matrix times (p, 1) (a pairwise tree): of the 15
// ways to sum the four terms only this one agreed with tckedit 3.0.3 on
// points placed a few ulps from voxel faces (tests/unit/voxel_mask_test.cpp
// keeps such points against tckedit).
// The voxel index is c rounded half away from zero, as std::round in
// tckedit: t = trunc(c), then t + sign(c) when |c - t| >= 0.5 (c - t is
// exact). Not floor(c + 0.5), whose sum rounds 0.49999997 up to 1, nor GLSL
// round(), whose halves are left to the implementation.
// p is inside when every index is in [0, size) and that voxel is set; a
// NaN coordinate compares false, so it is outside.
#ifndef FIBSCOPE_SHADERS_SHARED_VOXEL_MASK_H
#define FIBSCOPE_SHADERS_SHARED_VOXEL_MASK_H

#include "shared/glsl_cpp.h"

SHADER_NAMESPACE_BEGIN

SHADER_FN float voxelMaskCoordinate(vec4 row, vec3 p) {
  SHADER_PRECISE float xy = row.x * p.x + row.y * p.y;
  SHADER_PRECISE float zw = row.z * p.z + row.w;
  SHADER_PRECISE float c = xy + zw;
  return c;
}

SHADER_FN float roundHalfAwayFromZero(float c) {
  SHADER_PRECISE float t = trunc(c);
  SHADER_PRECISE float f = c - t;
  return abs(f) >= 0.5f ? t + (c < 0.0f ? -1.0f : 1.0f) : t;
}

SHADER_NAMESPACE_END

#endif  // FIBSCOPE_SHADERS_SHARED_VOXEL_MASK_H
