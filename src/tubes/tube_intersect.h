// Ray casting of the sphere-swept quadratic tubes (seed section 3.2): the
// CPU reference of glsl/tube_intersect.glsl (same algorithm, in double),
// an independent brute-force intersection to test both against, and CPU
// frames of a whole tube model with either.
//
// The model: a sub-segment (shared/tubes.h TubeQuadratic) is the union of
// the spheres S(t) of centre c(t) and radius r(t), t in [0, 1]. Along a
// ray o + s d (|d| = 1), sphere S(t) is hit where
//   g(t) = r(t)^2 - |h(t)|^2 >= 0,  h(t) = (c(t) - o) - ((c(t) - o).d) d,
// a polynomial of degree 4 in t (the seed's polyB), at the front distance
//   f(t) = z(t) - sqrt(g(t)),  z(t) = (c(t) - o).d.
// The surface's front hit is the minimum of f over {t : g(t) >= 0}. So:
//   1. the roots of g in [0, 1] by the bisection cascade: the roots of g''
//      in closed form split [0, 1] where g' is monotone, 10 bisections
//      find each root of g' (at most 3 searches), which split [0, 1] where
//      g is monotone, 10 bisections find each root of g (at most 4): the
//      seed's 7 searches of 10 iterations. Between them g >= 0 or g < 0.
//   2. on each interval where g >= 0, the minimum of f: at t = 0 or 1 if
//      the interval reaches them (the end spheres), else where f' changes
//      sign from - to +. f' has the sign of phi = 2 z' sqrt(g) - g', which
//      is < 0 at an interval's left root and > 0 at its right root (the
//      sphere grazing the ray), so each interval holds a minimum; phi is
//      sampled at 5 points over the interval and each - to + change
//      bisected 10 times (this step is ours: the seed's text leaves the
//      search of f_t's front to the shader).
// The hit's normal is the normal of the sphere S(t*) at the hit, which is
// the envelope's normal there.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "render/camera.h"
#include "shared/tubes.h"
#include "tubes/tube_model.h"

namespace fibscope {

struct TubeRayHit {
  bool hit = false;
  double distance = 0;  // s along the unit ray direction (mm), > 0
  double t = 0;         // sub-segment parameter of the sphere hit
  glm::dvec3 normal{0.0};
};

// The cascade above. `d` unit. Hits at s <= 0 (behind the origin) are not
// hits. Safe for any finite input; a radius control <= 0 draws nothing
// there.
TubeRayHit intersectTubeQuadratic(const shader::TubeQuadratic& q, const glm::dvec3& o, const glm::dvec3& d);

// Independent reference: the exact front root of each of `samples`
// spheres S(t_k) evenly spaced in t, the nearest refined by golden-section
// search of f over its neighbourhood. Slow; for tests.
TubeRayHit intersectTubeQuadraticBruteForce(const shader::TubeQuadratic& q, const glm::dvec3& o, const glm::dvec3& d,
                                            uint32_t samples = 4096);

// The quadratic's centre and radius at t (Bezier).
glm::dvec3 tubeQuadraticCenter(const shader::TubeQuadratic& q, double t);
double tubeQuadraticRadius(const shader::TubeQuadratic& q, double t);

// Sub-segment `index` (2 * segment + half) of the model.
shader::TubeQuadratic tubeSubSegment(const TubeModel& model, uint32_t index);

// One frame of a tube model on the CPU, per pixel (row-major, top row
// first, as the camera's conventions in shared/camera.h): the eye ray
// through the pixel centre against every sub-segment.
struct TubeReferenceImage {
  uint32_t width = 0, height = 0;
  std::vector<float> depth;      // clip depth z/w; 1 where nothing is hit
  std::vector<double> distance;  // along the eye ray (mm); 0 where nothing is hit
  std::vector<uint32_t> fiber;   // kNoFiberId where nothing is hit
  std::vector<float> position;   // along the fiber in points (TubeNode::point interpolated)
  std::vector<glm::vec3> normal;
  size_t covered() const;
  // A camera-sized image with nothing hit.
  static TubeReferenceImage empty(const Camera& camera);
};
enum class TubeReferenceMethod { Cascade, BruteForce };
TubeReferenceImage renderReferenceTubes(const TubeModel& model, const Camera& camera, TubeReferenceMethod method,
                                        uint32_t brute_force_samples = 4096);

// The eye ray through pixel (px, py)'s centre (unit direction), as
// sphere_surface.comp's pixelToEye makes it.
void tubePixelRay(const Camera& camera, uint32_t px, uint32_t py, glm::dvec3& origin, glm::dvec3& direction);

}  // namespace fibscope
