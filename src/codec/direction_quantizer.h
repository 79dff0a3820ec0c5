// Quantisation of a local segment direction to a fiblet code (fiblets paper
// appendix A, DESIGN.md section 5): the direction is clamped into the
// alpha-cap around +z, the cap is mapped uniformly onto the hemisphere
// (theta' = theta * (pi/2) / alpha, same azimuth) and the hemisphere point
// is quantised on the 16 x 16 half-octahedron grid. Decoding is
// decodeDirection (fiblet_decoder.h); the cell centres are the codes.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>

namespace fibscope {

// A direction's position on the 16 x 16 grid as continuous coordinates
// (u, v) in [0, 16]: cell (floor(u), floor(v)) is its code.
struct DirectionGrid {
  double u = 0, v = 0;
};

// The exact position, in double with trigonometry: the reference, and the
// open-loop encoder's quantiser (the paper's). `direction` need not be
// unit; a zero or non-finite one encodes as straight ahead.
DirectionGrid encodeDirectionGrid(const glm::dvec3& direction, double alpha);
// The code of the cell holding g.
uint32_t cellOf(DirectionGrid g);
// The code of the first cell (lowest u and v) of the size x size block of
// cells nearest g, kept inside the grid; the block always holds cellOf(g).
uint32_t blockOrigin(DirectionGrid g, int size);
// cellOf(encodeDirectionGrid(direction, alpha)).
uint32_t encodeDirection(const glm::dvec3& direction, double alpha);

// A fast blockOrigin(encodeDirectionGrid(d), 2) for the closed-loop
// encoder's inner loop, where d is the vector from the decoded point to
// the original point and so has a length close to the step. Such vectors
// go through a 256 x 256 table over the tangent plane of the cap, (x, y) /
// |d| in [-sin(alpha), sin(alpha)]^2, whose entries are the block of each
// bin's centre; 1 / |d| is one Newton step of rsqrt from 1 / step (no sqrt
// or division per point). Other vectors (length off by more than 20 %, or
// pointing backwards) take gridFromFormula: with u = sin^2(theta) and
// k = (pi/2) / alpha the octahedral coordinates are
// (x, y) * R / (R * (|x| + |y|) + C * |d|), R = sin(k theta) / sin(theta),
// C = cos(k theta), both even in theta and so smooth in u, read from
// tables over u. Near a half-cell border the block may be the neighbouring
// one (tested); it still holds the exact cell, and the closed loop only
// needs the nearest cells among its candidates.
class FastDirectionQuantizer {
 public:
  FastDirectionQuantizer(double alpha, double step);
  uint32_t block2(double x, double y, double z) const;
  // The position without the tangent-plane table (any length).
  DirectionGrid gridFromFormula(double x, double y, double z) const;

 private:
  static constexpr int kEntries = 2048;
  static constexpr int kPlaneBins = 256;
  double sin2_alpha_;
  double index_scale_;  // kEntries / sin^2(alpha)
  bool cap_is_hemisphere_;
  // R and C at u = i * sin^2(alpha) / kEntries.
  std::array<double, kEntries + 2> ratio_, cos_mapped_;
  double inv_step_, step2_;
  double plane_scale_;  // bins per unit of (x, y) / |d|
  std::array<uint8_t, kPlaneBins * kPlaneBins> plane_;
};

}  // namespace fibscope
