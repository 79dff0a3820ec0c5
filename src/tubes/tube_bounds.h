// Tight oriented bounding boxes of the ray-cast tubes' quadratic
// sub-segments (seed figure 17): the boxes the fragment-shader ray caster
// draws, one instance per sub-segment (src/tubes/gpu/tube_raster_stage.h).
// Its GLSL twin is shaders/glsl/tube_box.glsl (same steps, in float).
//
// The centre curve c(t) of a quadratic (shared/tubes.h TubeQuadratic) lies
// in the plane of its control polygon b0 b1 b2, so the box's axes are:
//   x: the chord b2 - b0 (b1 - b0 where the chord is zero),
//   y: b1 - b0 made orthogonal to x (in the polygon's plane; any unit
//      normal to x where the polygon is a line or a point),
//   z: x cross y (normal to the plane).
// On each axis a the swept spheres reach from min_t (c(t).a - r(t)) to
// max_t (c(t).a + r(t)), and c(t).a +- r(t) is itself a quadratic Bezier
// in t (controls b_i.a +- r_i), whose exact range is its end values and
// its extremum where the derivative vanishes inside (0, 1). So the box is
// the smallest one with these axes holding every sphere; it is padded by
// a little float slack (1e-4 of the largest radius, 1e-6 of the
// coordinates), as the shader's is.
#pragma once

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "shared/tubes.h"

namespace fibscope {

struct TubeOrientedBox {
  glm::vec3 origin{0.0f};        // q.b0's centre: local coordinates are axes^T (p - origin)
  glm::mat3 axes{1.0f};          // orthonormal columns x, y, z
  glm::vec3 lo{0.0f}, hi{0.0f};  // extents in local coordinates; lo > hi on an axis: empty
  bool contains(const glm::vec3& p, float slack = 0.0f) const;
  float volume() const;
};

// The box above. Safe for any finite input (a radius control <= 0 shrinks
// the box; all <= 0 can make it empty).
TubeOrientedBox tubeOrientedBox(const shader::TubeQuadratic& q);

// The axis-aligned box the compute caster bins and tests
// (glsl/tube_intersect.glsl tubeBox): the centre curve's extent per axis
// widened by the largest radius control.
void tubeAxisAlignedBox(const shader::TubeQuadratic& q, glm::vec3& lo, glm::vec3& hi);

}  // namespace fibscope
