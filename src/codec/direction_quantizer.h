// Quantisation of a local segment direction to a fiblet code (fiblets paper
// appendix A, DESIGN.md section 5): the direction is clamped into the
// alpha-cap around +z, the cap is mapped uniformly onto the hemisphere
// (theta' = theta * (pi/2) / alpha, same azimuth) and the hemisphere point
// is quantised on the 16 x 16 half-octahedron grid. Decoding is
// decodeDirection (fiblet_decoder.h); the cell centres are the codes.
#pragma once

#include <array>
#include <cstdint>

namespace fibscope {

// The exact nearest cell, in double with trigonometry: the reference, and
// the open-loop encoder's quantiser (the paper's). `direction` need not be
// unit; a zero or non-finite one encodes as straight ahead.
uint32_t encodeDirection(const double direction[3], double alpha);

// An approximation of the same mapping for the closed-loop encoder's inner
// loop, where the direction is the vector from the decoded point to the
// original point and so has a length close to the step. Such vectors go
// through a 256 x 256 table over the tangent plane of the cap, (x, y) / |d|
// in [-sin(alpha), sin(alpha)]^2, whose entries are encodeDirection of the
// bin centres; 1 / |d| is one Newton step of rsqrt from 1 / step (no sqrt or
// division per point). Other vectors (length off by more than 20 %, or
// pointing backwards) take the exact formula without trigonometry:
// with u = sin^2(theta) and k = (pi/2) / alpha the octahedral coordinates
// are (x, y) * R / (R * (|x| + |y|) + C * |d|), R = sin(k theta) /
// sin(theta), C = cos(k theta), both even in theta and so smooth in u, read
// from tables over u. The result is the exact cell or, within about 1/16 of
// a cell of a border (a few percent of directions), its neighbour (tested):
// harmless here, since the closed loop searches the neighbours anyway.
class FastDirectionQuantizer {
 public:
  FastDirectionQuantizer(double alpha, double step);
  uint32_t cell(double x, double y, double z) const;
  // The path without the tangent-plane table (any length).
  uint32_t cellFromFormula(double x, double y, double z) const;

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
