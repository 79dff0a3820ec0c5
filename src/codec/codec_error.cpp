#include "codec/codec_error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "core/error.h"

namespace fibscope {

CodecErrorMeter::CodecErrorMeter() : histogram_(kBins, 0) {}

void CodecErrorMeter::merge(const CodecErrorMeter& other) {
  for (size_t i = 0; i < kBins; ++i) histogram_[i] += other.histogram_[i];
  points_ += other.points_;
  sum_ += other.sum_;
  sum2_ += other.sum2_;
  max_ = std::max(max_, other.max_);
}

CodecErrorStats CodecErrorMeter::stats() const {
  CodecErrorStats s;
  s.points = points_;
  if (points_ == 0) return s;
  s.max_um = max_;
  s.mean_um = sum_ / double(points_);
  s.rms_um = std::sqrt(sum2_ / double(points_));
  // Nearest rank: the smallest bin upper edge with >= 99% of the points below.
  const auto rank = uint64_t(std::ceil(0.99 * double(points_)));
  uint64_t below = 0;
  for (size_t i = 0; i < kBins; ++i) {
    below += histogram_[i];
    if (below >= rank) {
      s.p99_um = std::min(double(i + 1) * kBinUm, max_);
      break;
    }
  }
  return s;
}

CodecErrorStats measureCodecError(const Tractogram& original, const EncodedFiblets& fiblets,
                                  const FibletDecoder& decoder, std::vector<float>* per_point_um) {
  if (const std::string problem = validateFiblets(fiblets, decoder.params()); !problem.empty())
    fail("fiblets", problem);
  if (fiblets.fiberCount() != original.streamlineCount())
    fail("fiblets", std::to_string(fiblets.fiberCount()) + " fibers, original has " +
                        std::to_string(original.streamlineCount()) + " streamlines");
  for (size_t s = 0; s < original.streamlineCount(); ++s)
    if (fiblets.fiber_points[s] != original.pointsIn(s))
      fail("fiblets", "fiber " + std::to_string(s) + " has " + std::to_string(fiblets.fiber_points[s]) +
                          " points, original has " + std::to_string(original.pointsIn(s)));
  if (per_point_um) per_point_um->resize(original.pointCount());
  CodecErrorMeter meter;
  std::array<float, 3 * shader::kFibletMaxPoints> xyz;
  size_t point = 0;  // validated: records hold exactly the original points, in order
  for (size_t i = 0; i < fiblets.fibletCount(); ++i) {
    const uint32_t count = decoder.decodeScan(fiblets.record(i), xyz.data());
    for (uint32_t k = 0; k < count; ++k, ++point) {
      const auto w = decoder.toWorld(&xyz[3 * k]);
      const float* p = original.point(point);
      const double dx = w[0] - p[0], dy = w[1] - p[1], dz = w[2] - p[2];
      const double um = std::sqrt(dx * dx + dy * dy + dz * dz) * 1000.0;
      meter.add(um);
      if (per_point_um) (*per_point_um)[point] = float(um);
    }
  }
  return meter.stats();
}

}  // namespace fibscope
