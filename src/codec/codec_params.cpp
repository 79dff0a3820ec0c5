#include "codec/codec_params.h"

#include <algorithm>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <cmath>
#include <glm/glm.hpp>
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

void CodecParamEstimator::push(SegmentSample sample) {
  samples_.push_back(sample);
  if (samples_.size() > std::max<size_t>(options_.max_samples, 2)) {
    // Keep every other sample: still every-k-th of the stream, k doubled.
    // The next one is 2k after the last kept sample.
    size_t kept = 0;
    for (size_t i = 0; i < samples_.size(); i += 2) samples_[kept++] = samples_[i];
    const bool last_kept = samples_.size() % 2 == 1;
    samples_.resize(kept);
    if (last_kept) next_sample_ += stride_;
    stride_ *= 2;
  }
}

CodecParamEstimator::CodecParamEstimator(const CodecParamOptions& options) : options_(options) {
  lo_f_.fill(std::numeric_limits<float>::infinity());
  hi_f_.fill(-std::numeric_limits<float>::infinity());
}

namespace {
// The tan^2 key of a turn of 90 degrees or more.
constexpr double kInfiniteTurn = 1e30;
// Turn angle in degrees from its tan^2 key.
double turnDegrees(double tan2) {
  return tan2 >= kInfiniteTurn ? 90.0 : std::atan(std::sqrt(tan2)) * 180.0 / std::numbers::pi;
}
}  // namespace

void CodecParamEstimator::add(const Tractogram& chunk) {
  // Every point enters the bounding box (exact); only sampled segments are
  // measured (see SegmentSample).
  // In locals: the members could alias the points for the compiler, which
  // then kept them in memory (a store-to-load chain per point).
  const float* p = chunk.positions.data();
  const size_t count = chunk.pointCount();
  float lx = lo_f_[0], ly = lo_f_[1], lz = lo_f_[2], hx = hi_f_[0], hy = hi_f_[1], hz = hi_f_[2];
  size_t next = 0;  // the first point not yet in the box
#if defined(__SSE2__)
  // Four points are three vectors (x y z x | y z x y | z x y z): one min and
  // one max per vector, with the lanes' components folded at the end. MINPS
  // returns its second operand when either is NaN, so a NaN point never
  // enters the box (the accumulator is the second operand).
  if (count >= 4) {
    __m128 lo[3], hi[3];
    for (int v = 0; v < 3; ++v) lo[v] = hi[v] = _mm_loadu_ps(p + 4 * v);
    for (int v = 0; v < 3; ++v) {
      // A NaN in the first four points must not seed the accumulators.
      const __m128 finite = _mm_cmpord_ps(lo[v], lo[v]);
      const __m128 seed_lo = _mm_set1_ps(std::numeric_limits<float>::infinity());
      lo[v] = _mm_or_ps(_mm_and_ps(finite, lo[v]), _mm_andnot_ps(finite, seed_lo));
      hi[v] = _mm_or_ps(_mm_and_ps(finite, hi[v]), _mm_andnot_ps(finite, _mm_sub_ps(_mm_setzero_ps(), seed_lo)));
    }
    for (next = 4; next + 4 <= count; next += 4) {
      for (int v = 0; v < 3; ++v) {
        const __m128 x = _mm_loadu_ps(p + 3 * next + 4 * v);
        lo[v] = _mm_min_ps(x, lo[v]);
        hi[v] = _mm_max_ps(x, hi[v]);
      }
    }
    float l[12], h[12];
    for (int v = 0; v < 3; ++v) {
      _mm_storeu_ps(l + 4 * v, lo[v]);
      _mm_storeu_ps(h + 4 * v, hi[v]);
    }
    // Lane k of the 12 holds component k % 3.
    for (int k = 0; k < 12; ++k) {
      float& lc = k % 3 == 0 ? lx : (k % 3 == 1 ? ly : lz);
      float& hc = k % 3 == 0 ? hx : (k % 3 == 1 ? hy : hz);
      lc = l[k] < lc ? l[k] : lc;
      hc = h[k] > hc ? h[k] : hc;
    }
  }
#endif
  for (const float* q = p + 3 * next; next < count; ++next, q += 3) {
    // NaN compares false and stays out of the box.
    lx = q[0] < lx ? q[0] : lx;
    ly = q[1] < ly ? q[1] : ly;
    lz = q[2] < lz ? q[2] : lz;
    hx = q[0] > hx ? q[0] : hx;
    hy = q[1] > hy ? q[1] : hy;
    hz = q[2] > hz ? q[2] : hz;
  }
  lo_f_ = {lx, ly, lz};
  hi_f_ = {hx, hy, hz};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t s = 0; s < chunk.streamlineCount(); ++s) {
    const size_t first = chunk.offsets[s], n = chunk.pointsIn(s);
    points_ += n;
    if (n < 2) continue;
    // Segments of this streamline are stream indices [segments_, end).
    const uint64_t end = segments_ + (n - 1);
    for (; next_sample_ < end; next_sample_ += stride_) {
      const size_t i = size_t(next_sample_ - segments_) + 1;  // the segment from point i - 1 to i
      const float* b = chunk.point(first + i);
      const float* a = b - 3;
      const glm::dvec3 d = glm::dvec3(b[0], b[1], b[2]) - glm::dvec3(a[0], a[1], a[2]);
      const double len2 = glm::dot(d, d);
      SegmentSample sample{std::isfinite(len2) ? float(std::sqrt(len2)) : nan, nan};
      if (i >= 2 && std::isfinite(len2) && len2 > 0) {
        const float* z = a - 3;
        const glm::dvec3 e = glm::dvec3(a[0], a[1], a[2]) - glm::dvec3(z[0], z[1], z[2]);
        const double prev2 = glm::dot(e, e);
        if (prev2 > 0 && std::isfinite(prev2)) {
          // tan^2 of the turn, |e x d|^2 / (e . d)^2: monotonic in the angle
          // below 90 degrees (turns beyond count as infinite), exact for
          // small turns where 1 - cos would cancel, and no acos per sample.
          // summary() converts the percentile.
          const double dot = glm::dot(d, e);
          const glm::dvec3 c = glm::cross(e, d);
          const double tan2 = dot > 0 ? glm::dot(c, c) / (dot * dot) : kInfiniteTurn;
          sample.turn = float(std::min(tan2, kInfiniteTurn));
        }
      }
      push(sample);
    }
    segments_ = end;
  }
}

// Largest bounding box side accepted, in mm: far beyond any head (or any
// animal scanned), small enough that an outlier coordinate is caught.
constexpr double kMaxExtentMm = 1e5;

CodecParamSummary CodecParamEstimator::summary(double step_tolerance) const {
  const std::string where = "codec parameters";
  if (points_ == 0) fail(where, "the tractogram has no points");
  CodecParamSummary out;
  out.points = points_;
  out.segments = segments_;
  std::vector<float> lengths, turns;
  for (const SegmentSample& sample : samples_) {
    if (std::isfinite(sample.length) && sample.length > 0) lengths.push_back(sample.length);
    if (!std::isnan(sample.turn)) turns.push_back(sample.turn);
  }
  out.sampled_steps = lengths.size();
  out.sampled_turns = turns.size();
  CodecParams& params = out.params;
  params.points_per_fiblet = options_.points_per_fiblet;
  std::array<double, 3> lo_, hi_;
  for (int c = 0; c < 3; ++c) {
    lo_[c] = lo_f_[c];
    hi_[c] = hi_f_[c];
    if (!std::isfinite(lo_[c]) || !std::isfinite(hi_[c])) fail(where, "no finite point to normalise");
  }
  const double extent = std::max({hi_[0] - lo_[0], hi_[1] - lo_[1], hi_[2] - lo_[2]});
  out.extent_mm = extent;
  if (extent > kMaxExtentMm) {
    int axis = 0;
    for (int c = 1; c < 3; ++c)
      if (hi_[c] - lo_[c] > hi_[axis] - lo_[axis]) axis = c;
    fail(where, "points span " + std::to_string(extent) + " mm along " + std::string(1, "xyz"[axis]) + " (from " +
                    std::to_string(lo_[axis]) + " to " + std::to_string(hi_[axis]) +
                    "): not a tractogram in mm, or an outlier coordinate");
  }
  // A single point (or a degenerate box) still gets a valid scale.
  const double scale = extent > 0 ? 1.0 / extent : 1.0;
  for (int c = 0; c < 3; ++c) params.translation[c] = float(lo_[c]);
  params.scale = float(scale);

  double delta_mm = options_.delta_mm;
  out.delta_measured = !(delta_mm > 0);
  if (out.delta_measured) {
    if (lengths.empty()) fail(where, "no segment of non-zero length to measure the step from");
    delta_mm = percentileOf(lengths, 50.0);
  }
  // Float coordinates in [0, 1] resolve 6e-8; a step of fewer than ~100
  // of those cannot hold a direction.
  if (extent > 0 && delta_mm / extent < 1e-5)
    fail(where, "step " + std::to_string(delta_mm) + " mm is too small for points spanning " + std::to_string(extent) +
                    " mm (float precision)");
  params.delta = float(delta_mm * double(params.scale));
  if (!lengths.empty()) {
    uint64_t off = 0;
    for (float l : lengths) off += std::fabs(double(l) - delta_mm) > step_tolerance * delta_mm;
    out.steps_off_fraction = double(off) / double(lengths.size());
  }

  double alpha_deg = options_.alpha_deg;
  out.alpha_measured = !(alpha_deg > 0);
  if (!turns.empty()) {
    out.max_turn_deg = turnDegrees(*std::max_element(turns.begin(), turns.end()));
    out.turn_percentile_deg = turnDegrees(percentileOf(turns, options_.alpha_percentile));
  }
  if (out.alpha_measured) alpha_deg = out.turn_percentile_deg * options_.alpha_margin;
  alpha_deg = std::clamp(alpha_deg, options_.min_alpha_deg, std::min(options_.max_alpha_deg, 90.0));
  params.alpha = std::min(float(alpha_deg * std::numbers::pi / 180.0), float(std::numbers::pi / 2));
  validateCodecParams(params);
  return out;
}

CodecParams chooseCodecParams(const Tractogram& tractogram, const CodecParamOptions& options) {
  CodecParamEstimator estimator(options);
  estimator.add(tractogram);
  return estimator.finish();
}

}  // namespace fibscope
