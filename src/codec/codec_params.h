// Fiblet codec parameters: normalisation, step, maximum angle, constant
// vector and fiblet size (DESIGN.md section 5), and how they are measured
// from data.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/tractogram.h"

namespace fibscope {

struct CodecParams {
  // World (RAS+ mm) -> normalised: n = (p - translation) * scale; the
  // tractogram's bounding box lands in [0,1]^3 (one uniform scale, so
  // angles and the step are the same in both spaces).
  std::array<float, 3> translation = {0, 0, 0};
  float scale = 1.0f;
  float delta = 0.001f;       // step in normalised units (delta_mm * scale)
  float alpha = 0.26179939f;  // maximum turn between segments, radians (0 < alpha <= pi/2)
  // The constant vector of the local frames. It lies on the equator of the
  // local frame (z = 0) while every code direction has z > 0.06, so it is
  // never collinear with one (tested over all codes and alphas).
  std::array<float, 3> v = {1.0f, 0.0f, 0.0f};
  uint32_t points_per_fiblet = 60;  // N: a multiple of 4 in [8, 60]

  double deltaMm() const { return double(delta) / double(scale); }
  uint32_t recordBytes() const;
};

// Throws Error("codec parameters: ...") when a value is out of range: N not
// a multiple of 4 in [8, 60], scale or delta not finite and > 0, alpha not in
// (0, pi/2], V not a finite unit vector with |V.z| <= 0.01, translation not
// finite. Safe on untrusted values (used on headers read from files).
void validateCodecParams(const CodecParams& params);

struct CodecParamOptions {
  uint32_t points_per_fiblet = 60;
  double delta_mm = 0;   // > 0: use this step instead of the median segment length
  double alpha_deg = 0;  // > 0: use this angle instead of measuring it
  // alpha = percentile(turning angles) * margin, clamped to [min, max].
  double alpha_percentile = 99.9;
  double alpha_margin = 1.1;
  double min_alpha_deg = 1.0;
  double max_alpha_deg = 90.0;
  // Bound on the estimator's memory (8 bytes a sample): 2^18 samples put ~260
  // turns above the 99.9th percentile, plenty for a stable alpha.
  size_t max_samples = size_t(1) << 18;
};

// What the estimator measured, for the compression report.
struct CodecParamSummary {
  CodecParams params;
  uint64_t points = 0;
  uint64_t segments = 0;       // finite segments seen
  uint64_t sampled_steps = 0;  // segment lengths in the sample
  uint64_t sampled_turns = 0;
  double turn_percentile_deg = 0;  // the alpha_percentile-th percentile of the sampled turns
  double max_turn_deg = 0;         // the largest sampled turn (compressTractogram puts the exact one here)
  // Fraction of the sampled segments whose length is off delta by more than
  // `step_tolerance` (the encoder's split threshold): resampled or
  // compressed inputs have many.
  double steps_off_fraction = 0;
  double extent_mm = 0;         // largest side of the bounding box
  bool alpha_measured = false;  // false when given
  bool delta_measured = false;
};

// Measures the statistics behind CodecParams from a stream of chunks in
// bounded memory: the exact bounding box, and a deterministic sample of
// segment lengths and turning angles (every k-th value, k doubling whenever
// the sample outgrows options.max_samples).
class CodecParamEstimator {
 public:
  explicit CodecParamEstimator(const CodecParamOptions& options = {});
  void add(const Tractogram& chunk);
  // delta = median segment length (trackers use one constant step; the
  // median ignores the short last segments and rare outliers). alpha = the
  // alpha_percentile-th percentile of the turning angles times alpha_margin,
  // so that the quantisation cells are sized for the bulk of the turns and
  // not for the rarest one; turns above alpha become split exceptions in the
  // encoder. Throws Error when no point was seen or every segment has zero
  // length (and no delta_mm was given).
  // Also throws when the bounding box is absurd for a tractogram in mm
  // (more than 100 m: an outlier coordinate would crush every other point
  // into a few quantisation steps) or delta is too small for float precision
  // at that scale.
  CodecParams finish() const { return summary().params; }
  CodecParamSummary summary(double step_tolerance = 0.05) const;

 private:
  // A deterministic sample of the segments: every stride-th segment of the
  // stream (in stream order), stride doubling whenever the sample outgrows
  // max_samples. Segments between samples are skipped without a look.
  struct SegmentSample {
    float length;  // mm; NaN when not finite
    float turn;    // tan^2 of the turn into this segment (see add()); NaN when none
  };
  void push(SegmentSample sample);
  CodecParamOptions options_;
  std::array<double, 3> lo_, hi_;
  std::array<float, 3> lo_f_, hi_f_;  // the box in float (the points are floats: exact)
  uint64_t points_ = 0;
  uint64_t segments_ = 0;
  std::vector<SegmentSample> samples_;
  uint64_t stride_ = 1;
  uint64_t next_sample_ = 0;  // stream index of the next sampled segment
};

// chooseCodecParams(t) = an estimator fed with the whole of t.
CodecParams chooseCodecParams(const Tractogram& tractogram, const CodecParamOptions& options = {});

// The value at percentile p (0..100) of `values` (nearest rank; reorders
// them). Requires a non-empty vector.
float percentileOf(std::vector<float>& values, double p);

}  // namespace fibscope
