#include "codec/codec_params.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.h"
#include "shared/fiblet.h"

namespace fibscope {

uint32_t CodecParams::recordBytes() const { return shader::fibletRecordBytes(points_per_fiblet); }

void validateCodecParams(const CodecParams& params) {
  const std::string where = "codec parameters";
  const uint32_t n = params.points_per_fiblet;
  if (n < shader::kFibletMinPoints || n > shader::kFibletMaxPoints || n % 4 != 0)
    fail(where, "points per fiblet must be a multiple of 4 in [8, 60], found " + std::to_string(n));
  if (!std::isfinite(params.scale) || !(params.scale > 0))
    fail(where, "scale must be finite and > 0, found " + std::to_string(params.scale));
  if (!std::isfinite(params.delta) || !(params.delta > 0))
    fail(where, "step must be finite and > 0, found " + std::to_string(params.delta));
  if (!std::isfinite(params.alpha) || !(params.alpha > 0) || params.alpha > float(std::numbers::pi / 2))
    fail(where, "maximum angle must be in (0, pi/2] radians, found " + std::to_string(params.alpha));
  for (float t : params.translation)
    if (!std::isfinite(t)) fail(where, "translation must be finite");
  const auto& v = params.v;
  const double norm = std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
  if (!std::isfinite(norm) || std::fabs(norm - 1.0) > 1e-4 || std::fabs(v[2]) > 0.01f)
    fail(where, "constant vector V must be a unit vector with |z| <= 0.01, found (" + std::to_string(v[0]) + ", " +
                    std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")");
}

float percentileOf(std::vector<float>& values, double p) {
  const double rank = std::clamp(p / 100.0, 0.0, 1.0) * double(values.size() - 1);
  const auto index = size_t(std::llround(rank));
  std::nth_element(values.begin(), values.begin() + ptrdiff_t(index), values.end());
  return values[index];
}

void CodecParamEstimator::Sample::push(float value, size_t max_samples) {
  if (seen++ % stride != 0) return;
  values.push_back(value);
  if (values.size() > std::max<size_t>(max_samples, 2)) {
    // Keep every other value: the sample stays every-k-th of the stream.
    size_t kept = 0;
    for (size_t i = 0; i < values.size(); i += 2) values[kept++] = values[i];
    values.resize(kept);
    stride *= 2;
  }
}

CodecParamEstimator::CodecParamEstimator(const CodecParamOptions& options) : options_(options) {
  lo_.fill(std::numeric_limits<double>::infinity());
  hi_.fill(-std::numeric_limits<double>::infinity());
}

void CodecParamEstimator::add(const Tractogram& chunk) {
  for (size_t s = 0; s < chunk.streamlineCount(); ++s) {
    const size_t first = chunk.offsets[s], n = chunk.pointsIn(s);
    double prev[3] = {0, 0, 0};
    bool have_prev = false;
    for (size_t i = 0; i < n; ++i) {
      const float* p = chunk.point(first + i);
      for (int c = 0; c < 3; ++c) {
        lo_[c] = std::min(lo_[c], double(p[c]));
        hi_[c] = std::max(hi_[c], double(p[c]));
      }
      if (i == 0) continue;
      const float* q = chunk.point(first + i - 1);
      const double d[3] = {double(p[0]) - q[0], double(p[1]) - q[1], double(p[2]) - q[2]};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      if (!std::isfinite(len)) {  // a NaN or infinite point: no step or turn to measure here
        have_prev = false;
        continue;
      }
      lengths_.push(float(len), options_.max_samples);
      if (len > 0 && have_prev) {
        const double c = (d[0] * prev[0] + d[1] * prev[1] + d[2] * prev[2]) / len;
        angles_.push(float(std::acos(std::clamp(c, -1.0, 1.0))), options_.max_samples);
      }
      if (len > 0) {
        for (int c = 0; c < 3; ++c) prev[c] = d[c] / len;
        have_prev = true;
      }
    }
    points_ += n;
  }
}

CodecParams CodecParamEstimator::finish() const {
  const std::string where = "codec parameters";
  if (points_ == 0) fail(where, "the tractogram has no points");
  CodecParams params;
  params.points_per_fiblet = options_.points_per_fiblet;
  const double extent = std::max({hi_[0] - lo_[0], hi_[1] - lo_[1], hi_[2] - lo_[2]});
  // A single point (or a degenerate box) still gets a valid scale.
  const double scale = extent > 0 ? 1.0 / extent : 1.0;
  for (int c = 0; c < 3; ++c) params.translation[c] = float(lo_[c]);
  params.scale = float(scale);

  double delta_mm = options_.delta_mm;
  if (!(delta_mm > 0)) {
    std::vector<float> lengths = lengths_.values;
    std::erase_if(lengths, [](float l) { return !(l > 0); });
    if (lengths.empty()) fail(where, "no segment of non-zero length to measure the step from");
    delta_mm = percentileOf(lengths, 50.0);
  }
  params.delta = float(delta_mm * double(params.scale));

  double alpha_deg = options_.alpha_deg;
  if (!(alpha_deg > 0)) {
    std::vector<float> angles = angles_.values;
    const double measured =
        angles.empty() ? 0.0 : double(percentileOf(angles, options_.alpha_percentile)) * 180.0 / std::numbers::pi;
    alpha_deg = measured * options_.alpha_margin;
  }
  alpha_deg = std::clamp(alpha_deg, options_.min_alpha_deg, std::min(options_.max_alpha_deg, 90.0));
  params.alpha = std::min(float(alpha_deg * std::numbers::pi / 180.0), float(std::numbers::pi / 2));
  validateCodecParams(params);
  return params;
}

CodecParams chooseCodecParams(const Tractogram& tractogram, const CodecParamOptions& options) {
  CodecParamEstimator estimator(options);
  estimator.add(tractogram);
  return estimator.finish();
}

}  // namespace fibscope
