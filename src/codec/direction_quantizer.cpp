#include "codec/direction_quantizer.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "shared/fiblet.h"

namespace fibscope {

namespace {

// Octahedral coordinates (ox, oy) of a hemisphere point -> continuous grid
// coordinates: the 45-degree rotation onto the square [-1, 1]^2 (see
// fibletOctahedralCell), scaled to [0, 16].
DirectionGrid gridOf(double ox, double oy) { return {(ox + oy + 1.0) * 8.0, (ox - oy + 1.0) * 8.0}; }

// floor(c) clamped to [0, limit] (NaN -> 0).
uint32_t clampedFloor(double c, uint32_t limit) { return c >= double(limit) ? limit : (c > 0 ? uint32_t(c) : 0u); }

}  // namespace

uint32_t cellOf(DirectionGrid g) {
  const uint32_t last = shader::kFibletGridSize - 1;
  return clampedFloor(g.u, last) << 4 | clampedFloor(g.v, last);
}

uint32_t blockOrigin(DirectionGrid g, int size) {
  // The size cells nearest to g along an axis start at floor(g - (size - 1) / 2).
  const double shift = 0.5 * double(size - 1);
  const uint32_t last = shader::kFibletGridSize - uint32_t(size);
  return clampedFloor(g.u - shift, last) << 4 | clampedFloor(g.v - shift, last);
}

DirectionGrid encodeDirectionGrid(const glm::dvec3& direction, double alpha) {
  const double norm = glm::length(direction);
  double x = 0, y = 0, z = 1;
  // Non-finite input (NaN points) encodes as straight ahead rather than
  // reaching an out-of-range float -> int conversion.
  if (norm > 0 && std::isfinite(norm)) {
    x = direction[0] / norm;
    y = direction[1] / norm;
    z = direction[2] / norm;
  }
  const double theta = std::min(std::acos(std::clamp(z, -1.0, 1.0)), alpha);
  const double phi = std::atan2(y, x);
  const double theta_h = theta * (std::numbers::pi / 2) / alpha;
  const double hx = std::sin(theta_h) * std::cos(phi), hy = std::sin(theta_h) * std::sin(phi);
  // Onto the octahedron |x| + |y| + z = 1 (cos(theta_h) >= 0 up to rounding).
  const double s = std::fabs(hx) + std::fabs(hy) + std::max(std::cos(theta_h), 0.0);
  return gridOf(hx / s, hy / s);
}

uint32_t encodeDirection(const glm::dvec3& direction, double alpha) {
  return cellOf(encodeDirectionGrid(direction, alpha));
}

FastDirectionQuantizer::FastDirectionQuantizer(double alpha, double step)
    : sin2_alpha_(std::pow(std::sin(alpha), 2)),
      index_scale_(kEntries / std::pow(std::sin(alpha), 2)),
      cap_is_hemisphere_(alpha >= std::numbers::pi / 2) {
  const double k = (std::numbers::pi / 2) / alpha;
  for (int i = 0; i < kEntries + 2; ++i) {
    const double u = std::min(double(i) / kEntries, 1.0) * sin2_alpha_;
    const double theta = std::min(std::asin(std::sqrt(u)), alpha);
    // R(0) is the limit k.
    ratio_[size_t(i)] = theta > 0 ? std::sin(k * theta) / std::sin(theta) : k;
    cos_mapped_[size_t(i)] = std::cos(k * theta);
  }
  inv_step_ = 1.0 / step;
  step2_ = step * step;
  const double half_width = std::sin(alpha);
  plane_scale_ = kPlaneBins / (2 * half_width);
  for (int i = 0; i < kPlaneBins; ++i) {
    for (int j = 0; j < kPlaneBins; ++j) {
      const double dx = ((i + 0.5) / plane_scale_) - half_width, dy = ((j + 0.5) / plane_scale_) - half_width;
      const double r2 = dx * dx + dy * dy;
      // Outside the unit disc: on the equator, i.e. beyond the cap (clamped to the rim).
      const glm::dvec3 dir(dx, dy, r2 < 1 ? std::sqrt(1 - r2) : 0.0);
      plane_[size_t(i * kPlaneBins + j)] = uint8_t(blockOrigin(encodeDirectionGrid(dir, alpha), 2));
    }
  }
}

uint32_t FastDirectionQuantizer::block2(double x, double y, double z) const {
  const double n2 = x * x + y * y + z * z;
  // Lengths within 20 % of the step: one Newton step from 1 / step gives
  // 1 / |d| to better than 2 % (relative error 3/8 e^2 for n2 = step^2 (1 + e)).
  if (z > 0 && n2 > 0.64 * step2_ && n2 < 1.44 * step2_) {
    const double inv_n = inv_step_ * (1.5 - 0.5 * n2 * inv_step_ * inv_step_);
    const double half = kPlaneBins / 2;
    const double fi = x * inv_n * plane_scale_ + half, fj = y * inv_n * plane_scale_ + half;
    // Beyond the square: the cap's rim; clamping the bin keeps the azimuth
    // roughly (those cells are exceptions to the table's accuracy claim, and
    // rare: the goal lies outside the cap only after a turn of alpha).
    const int i = fi <= 0 ? 0 : (fi >= kPlaneBins - 1 ? kPlaneBins - 1 : int(fi));
    const int j = fj <= 0 ? 0 : (fj >= kPlaneBins - 1 ? kPlaneBins - 1 : int(fj));
    return plane_[size_t(i * kPlaneBins + j)];
  }
  return blockOrigin(gridFromFormula(x, y, z), 2);
}

DirectionGrid FastDirectionQuantizer::gridFromFormula(double x, double y, double z) const {
  const double r2 = x * x + y * y;
  const double n2 = r2 + z * z;
  // Zero or non-finite input: straight ahead, as encodeDirection.
  if (!(n2 > 0) || !std::isfinite(n2)) return gridOf(0, 0);
  const double u = r2 / n2;
  // Beyond the cap (or behind, z <= 0) the direction is clamped to the rim:
  // the mapped angle is pi/2, on the equator of the hemisphere.
  if (z <= 0 || (!cap_is_hemisphere_ && u >= sin2_alpha_)) {
    const double s = std::fabs(x) + std::fabs(y);
    if (s == 0) return gridOf(1, 0);  // straight back: encodeDirection's atan2(0, 0) = 0
    return gridOf(x / s, y / s);
  }
  const double f = u * index_scale_;
  const auto i = std::min(size_t(f), size_t(kEntries));
  const double w = f - double(i);
  const double ratio = ratio_[i] + w * (ratio_[i + 1] - ratio_[i]);
  const double cos_h = cos_mapped_[i] + w * (cos_mapped_[i + 1] - cos_mapped_[i]);
  const double scale = ratio / (ratio * (std::fabs(x) + std::fabs(y)) + cos_h * std::sqrt(n2));
  return gridOf(x * scale, y * scale);
}

}  // namespace fibscope
