// Phantom statistics: one pass over a sample of streamlines.
#include "phantom/phantom_stats.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "io/tractogram_stats.h"

namespace fibscope {

PhantomEstimate estimatePhantom(const PhantomOptions& options, uint64_t sample_streamlines) {
  PhantomOptions sample_options = options;
  sample_options.streamlines = std::min(options.streamlines, sample_streamlines);
  const auto start = std::chrono::steady_clock::now();
  auto reader = openPhantom(sample_options);

  // The geometry is measured as `fibscope info` measures any tractogram.
  TractogramStatsAccumulator stats;
  PhantomEstimate e;
  Tractogram chunk;
  while (reader->read(chunk)) {
    stats.add(chunk);
    for (float bundle : chunk.per_streamline[0].values)
      if (size_t(bundle) < kPhantomBundleCount) ++e.bundle_streamlines[size_t(bundle)];
  }
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const TractogramStats s = stats.result();
  e.sampled_streamlines = s.streamlines;
  e.sampled_points = s.points;
  e.sampled_segments = s.segments;
  if (s.streamlines == 0) return e;
  e.length_mean_mm = s.length_mean;
  e.length_min_mm = s.length_min;
  e.length_max_mm = s.length_max;
  e.segment_min_mm = s.step_min;
  e.segment_max_mm = s.step_max;
  e.turn_mean_deg = s.angle_mean_deg;
  e.turn_p50_deg = s.angle_p50_deg;
  e.turn_p99_deg = s.angle_p99_deg;
  e.turn_p999_deg = s.angle_p999_deg;
  e.turn_max_deg = s.angle_max_deg;

  const double points_per_streamline = double(e.sampled_points) / double(e.sampled_streamlines);
  if (e.sampled_streamlines == options.streamlines) {
    e.projected_points = e.sampled_points;
  } else {
    e.projected_points = uint64_t(std::llround(points_per_streamline * double(options.streamlines)));
  }
  e.projected_segments = e.projected_points - std::min(e.projected_points, options.streamlines);
  return e;
}

}  // namespace fibscope
