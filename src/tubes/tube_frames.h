// Cross-section frames of the spline tubes (seed section 3.1, figure 6):
// rotation-minimising frames propagated along each tube by double
// reflection (Wang, Juettler, Zheng and Liu, "Computation of rotation
// minimizing frames", ACM TOG 2008), so the rings of a tessellated tube
// never twist. Between two nodes whose tangents turn by more than a given
// angle the frame is carried through sub-steps along the Hermite curve
// (a single reflection pair across a turn near 90 degrees is no longer a
// good approximation of the rotation-minimising motion).
#pragma once

#include <cstddef>

#include <glm/vec3.hpp>

#include "shared/tubes.h"

namespace fibscope {

// One double-reflection step: the frame vector r0 (unit, normal to t0) at
// point x0 with unit tangent t0, carried to x1 with unit tangent t1.
// Returns a unit vector normal to t1.
glm::vec3 doubleReflection(const glm::vec3& x0, const glm::vec3& t0, const glm::vec3& r0, const glm::vec3& x1,
                           const glm::vec3& t1);

// A unit vector normal to the unit vector t (the frame a tube starts with).
glm::vec3 anyNormal(const glm::vec3& t);

// Writes TubeNode::normal of the `count` nodes of one tube, whose count - 1
// segments are `segments` (segment k joins nodes k and k + 1): the start
// frame from anyNormal (or `start`, when not null: unit, normal to the
// first tangent), then double reflection node to node, in
// ceil(turn / substep_degrees) sub-steps along the Hermite curve where the
// tangents turn by more than substep_degrees. Returns the sub-steps taken
// beyond one per segment.
size_t propagateTubeFrames(shader::TubeNode* nodes, const shader::TubeSegment* segments, size_t count,
                           float substep_degrees, const glm::vec3* start = nullptr);

}  // namespace fibscope
