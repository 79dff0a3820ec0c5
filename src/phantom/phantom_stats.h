// Size and tracker statistics of a phantom, measured on a sample of its
// streamlines and projected to the whole phantom: what `fibscope phantom`
// will write (points, segments, bytes) before writing it, and the figures
// that say it looks like tracker output (lengths, steps, turning angles).
#pragma once

#include <array>
#include <cstdint>

#include "phantom/phantom.h"

namespace fibscope {

struct PhantomEstimate {
  // The sample: streamlines [0, sampled_streamlines) of the phantom. Every
  // streamline is an independent draw, so the first n are a fair sample.
  uint64_t sampled_streamlines = 0;
  uint64_t sampled_points = 0;
  uint64_t sampled_segments = 0;
  double seconds = 0;  // wall time spent generating and measuring the sample

  // Streamline lengths (sum of segment lengths between the stored float
  // points, in double), mm.
  double length_mean_mm = 0, length_min_mm = 0, length_max_mm = 0;
  // Segment lengths, mm.
  double segment_min_mm = 0, segment_max_mm = 0;
  // Turning angle between consecutive segments, degrees; percentiles from a
  // histogram of 0.001-degree bins (upper bin edge), as TractogramStats.
  double turn_mean_deg = 0, turn_p50_deg = 0, turn_p99_deg = 0, turn_p999_deg = 0, turn_max_deg = 0;
  std::array<uint64_t, kPhantomBundleCount> bundle_streamlines{};

  // Projection to options.streamlines (exact when the sample is the whole
  // phantom).
  uint64_t projected_points = 0;
  uint64_t projected_segments = 0;
};

// Generates streamlines [0, min(sample_streamlines, options.streamlines))
// of the phantom with `options` (on options.threads threads) and measures
// them. Throws Error for invalid options.
PhantomEstimate estimatePhantom(const PhantomOptions& options, uint64_t sample_streamlines);

}  // namespace fibscope
