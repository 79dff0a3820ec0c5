// Fiblet encoder (DESIGN.md section 5): streamlines in world mm -> fixed-size
// fiblet records and per-fiber tables, in the paper's open-loop mode or the
// closed-loop mode that runs the decoder alongside.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>

#include "codec/codec_error.h"
#include "codec/codec_params.h"
#include "codec/direction_quantizer.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_simd.h"
#include "core/tractogram.h"

namespace fibscope {

enum class EncodeMode : uint8_t {
  // The paper's scheme (section 3.2), `compress --open-loop`: the true
  // direction of each segment, expressed in the frame the decoder will have
  // there (propagated from the previously *decoded* directions; the decoder
  // knows no other), quantised to the nearest code. Heading errors do not
  // accumulate, position errors do, as a random walk along the fiblet.
  OpenLoop,
  // A naive variant kept to show why the frame must be the decoded one:
  // directions in the frame of the previous *true* direction. The decoded
  // path drifts by millimetres (the 16 x 16 grid has no code on the forward
  // axis, so a straight run is biased the same way at every step).
  TrueFrame,
  // The default: at each point, among the (2r+1)^2 cells around the one
  // aimed from the decoded point and frame at the original point, the code
  // whose decoded point lands nearest the original point, so errors do not
  // accumulate.
  ClosedLoop,
};

struct EncodeOptions {
  EncodeMode mode = EncodeMode::ClosedLoop;
  // Closed loop: the side of the block of cells searched around the
  // direction aimed from the decoded point at the original point (the
  // size x size cells nearest it). The decoded points of all codes lie on
  // the sphere of radius delta, so the nearest one is the code nearest in
  // angle, next to the aimed direction: 2 x 2, 3 x 3 and 5 x 5 gave the same
  // errors on the 300-fiber phantom and on MRtrix3 iFOD1 and SD_Stream output
  // at 0.1 mm (2026-11-22); 1 x 1 gave a 0.3-0.8 % larger mean (phantom max
  // 2.99 instead of 2.78 um). The phantom comparison is a test.
  int search_size = 2;
  // A segment whose length differs from delta by more than this fraction of
  // delta starts a new fiblet (the segment becomes the join between two
  // fiblets, which stores both its ends exactly).
  double step_tolerance = 0.05;
  // Closed loop only: a point that would decode farther than this many
  // deltas from the original starts a new fiblet instead (rare: it happens
  // when the decoded frame has lagged behind a sharp run of turns).
  double max_point_error = 0.15;
};

// What the encoder did, summed over everything encoded so far.
struct EncodeReport {
  uint64_t fibers = 0;
  uint64_t points = 0;
  uint64_t fiblets = 0;
  uint64_t angle_splits = 0;  // turns above alpha
  uint64_t step_splits = 0;   // steps off delta by more than the tolerance
  uint64_t error_splits = 0;  // closed-loop points that would exceed max_point_error
  uint64_t single_point_fibers = 0;
  uint64_t two_point_fibers = 0;
  uint64_t clamped_points = 0;  // stored points outside the normalisation box or not finite (clamped to [0,1]^3)
  // The largest turn between consecutive segments seen, as the smallest
  // sign(cos) * cos^2 (no acos per point); maxTurnDegrees() converts.
  double min_signed_cos2 = 1;

  double maxTurnDegrees() const;

  uint64_t splits() const { return angle_splits + step_splits + error_splits; }
  // Adds the counts of another encoder (one per thread).
  void merge(const EncodeReport& other);
};

class FibletEncoder {
 public:
  // Throws Error when the parameters are invalid.
  FibletEncoder(const CodecParams& params, const EncodeOptions& options = {});

  // Appends the fiblets and the table entries of one streamline (n points,
  // x,y,z interleaved, world mm) to `out`. Global fiblet indices count from
  // out.fiblet_base; a caller that streams may write out and clear
  // out.bytes and the tables between calls if it advances fiblet_base.
  void encodeStreamline(const float* xyz, size_t n, EncodedFiblets& out);
  void encode(const Tractogram& chunk, EncodedFiblets& out);

  // Measures every encoded point as the sequential decode reconstructs it
  // (the encoder runs that decode anyway), in um of world space, into
  // `meter` (nullptr: off). Non-finite input points are not measured (they
  // are counted as clamped). The GPU's log-step decode differs from the
  // sequential one by < 1e-6 of the scene size (tested).
  void setErrorMeter(CodecErrorMeter* meter) { meter_ = meter; }

  const EncodeReport& report() const { return report_; }
  const FibletDecoder& decoder() const { return decoder_; }

 private:
  // One fiber being encoded, a fiblet at a time; encode() runs kLanes at once.
  struct Lane {
    std::vector<double> target;  // the fiber in normalised space
    std::vector<uint8_t> bytes;  // records of the fibers this lane encoded
    std::vector<V4f> decoded;    // with a meter: the fiber's decoded points (normalised)
    size_t fiber = 0, n = 0;     // which fiber of the chunk, its point count
    size_t fiber_offset = 0;     // where its records start in bytes
    uint32_t fiber_fiblets = 0;
    // The fiblet in progress: points [first, first + count), the next point
    // k, at most count_max points; its record at bytes[base].
    size_t first = 0, k = 0, count = 0, count_max = 0, base = 0;
    Frame4 w;                         // the decoder's frame after point k - 1
    shader::FibletTransform truth{};  // TrueFrame mode only
    bool active = false;
  };
  struct Placement {
    uint8_t lane = 0;
    size_t offset = 0;
    uint32_t fiblets = 0;
  };
  void startFiber(Lane& lane, const float* xyz, size_t n);
  // Writes points 0 and 1 of a fiblet starting at lane.first.
  void startFiblet(Lane& lane);
  // Encodes point lane.k; false when the fiblet is complete (full, the
  // fiber's end, or an exception that starts a new fiblet at lane.k).
  bool stepFiblet(Lane& lane);
  // Writes the flags; starts the next fiblet and returns true, or returns
  // false at the end of the fiber.
  bool finishFiblet(Lane& lane);
  void emit(const Lane& lane, size_t offset, uint32_t fiblets, uint32_t points, EncodedFiblets& out);
  void checkOutput(EncodedFiblets& out) const;
  // Adds the errors of the lane's finished fiber to the meter.
  void measureFiber(const Lane& lane);
  // Records the turn at interior point j of the lane's fiber.
  void noteTurn(const Lane& lane, size_t j);
  // Records a turn given as dot(prev, seg), |seg|^2 and |prev|^2.
  void noteTurn(double dot, double len2, double prev2) {
    const double signed_dot2 = dot >= 0 ? dot * dot : -dot * dot;
    const double bound = report_.min_signed_cos2 * len2 * prev2;
    if (signed_dot2 < bound && len2 > 0 && prev2 > 0) report_.min_signed_cos2 = signed_dot2 / (len2 * prev2);
  }

  CodecParams params_;
  EncodeOptions options_;
  FibletDecoder decoder_;
  FastDirectionQuantizer quantizer_;
  // Closed loop: the code among options_.search_size^2 cells around the
  // direction of `local` whose step lands nearest `local` (the original
  // point in the decoded frame); returns the squared distance.
  float search(const glm::dvec3& local, uint32_t& code) const;
  struct Block {
    V4f x, y, z;  // steps of the 2 x 2 cells at an origin, row-major
  };
  std::array<Block, shader::kFibletCodeCount> blocks_{};
  // The translation of L_c for each code c as three arrays (padded so that
  // four-lane loads at any cell stay inside), and L_c as Frame4.
  std::array<float, shader::kFibletCodeCount + 4> step_x_, step_y_, step_z_;
  std::array<Frame4, shader::kFibletCodeCount> local4_;
  EncodeReport report_;
  CodecErrorMeter* meter_ = nullptr;
  double um2_per_unit2_;  // (world micrometres per normalised unit)^2
  shader::vec3 v_;
  double len2_lo_, len2_hi_;  // accepted squared step lengths (step_tolerance)
  double cos_alpha_, cos2_alpha_;
  double max_error2_;  // closed loop: squared max_point_error
  // Measured single-threaded on the phantom: 1 lane 20.5 M points/s, 2 lanes
  // 30, 3 and 4 lanes 30 (the out-of-order window holds about two steps).
  static constexpr size_t kLanes = 2;
  Lane lanes_[kLanes];
  std::vector<Placement> placements_;
};

// Encodes a whole tractogram; `report` (optional) receives the counts.
EncodedFiblets encodeTractogram(const Tractogram& tractogram, const CodecParams& params,
                                const EncodeOptions& options = {}, EncodeReport* report = nullptr);

struct ResampleReport {
  uint64_t input_points = 0;
  uint64_t output_points = 0;
  uint64_t moved_points = 0;  // output points that are not an input point
  // What the resampling cost: distance of each input point to the resampled
  // polyline (the chord between the output points around it), in mm.
  double max_deviation_mm = 0;
  double mean_deviation_mm = 0;
  uint64_t measured_points = 0;  // interior input points behind the mean

  // Adds the counts of another part of the same tractogram.
  void merge(const ResampleReport& other);
};

// Resamples every streamline so that consecutive points are step_mm apart
// (chord length, the step the decoder uses): each new point is where the
// sphere of radius step_mm around the previous one leaves the polyline. The
// first and last input points are kept; the last segment is shorter (the
// encoder stores it as a step exception). Per-point data arrays are
// interpolated linearly between the two input points around each new point
// (by its parameter on that segment, as the position). Throws Error when step_mm is not finite
// and > 0, a coordinate is not finite, or a streamline would need more than
// 2^31 points.
Tractogram resampleToStep(const Tractogram& tractogram, double step_mm, ResampleReport* report = nullptr);

}  // namespace fibscope
