// Error statistics of the fiblet codec: every point decoded (as the GPU
// decodes it, by the log-step scan) and compared with the original point in
// world space. Figures in micrometres (DESIGN.md section 4).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "codec/codec_params.h"
#include "codec/fiblet_decoder.h"
#include "core/tractogram.h"

namespace fibscope {

struct CodecErrorStats {
  uint64_t points = 0;
  double max_um = 0;
  double mean_um = 0;
  double rms_um = 0;
  double p99_um = 0;  // from a 0.01 um histogram (exact to 0.01 um below 1 mm)
};

// Accumulates point distances in bounded memory (a fixed histogram), so
// error statistics of any size of tractogram can be streamed.
// Aligned to a cache line: the compressor keeps one per worker thread in a
// vector, and neighbours sharing a line made every point a cache miss.
class alignas(64) CodecErrorMeter {
 public:
  CodecErrorMeter();
  // Inline: the encoder measures every point it encodes.
  void add(double distance_um) {
    ++points_;
    sum_ += distance_um;
    sum2_ += distance_um * distance_um;
    max_ = distance_um > max_ ? distance_um : max_;
    // Multiply and truncate (distances are >= 0): std::floor and a division
    // per point were a fifth of the compressor's time.
    const double bin = distance_um * (1.0 / kBinUm);
    histogram_[bin < double(kBins - 1) ? size_t(bin) : kBins - 1] += 1;
  }
  // Adds the points of another meter (one meter per encoding thread).
  void merge(const CodecErrorMeter& other);
  CodecErrorStats stats() const;

 private:
  static constexpr double kBinUm = 0.01;
  static constexpr size_t kBins = 100000;  // up to 1 mm; beyond goes to the last bin
  std::vector<uint64_t> histogram_;
  uint64_t points_ = 0;
  double sum_ = 0, sum2_ = 0, max_ = 0;
};

// Decodes `fiblets` and measures each point against `original` (same
// streamlines, same order, same point counts). `per_point_um`, when given,
// receives the distance of every point. Throws Error("fiblets: ...") when the
// fiblets are inconsistent or do not match the original's point counts.
CodecErrorStats measureCodecError(const Tractogram& original, const EncodedFiblets& fiblets,
                                  const FibletDecoder& decoder, std::vector<float>* per_point_um = nullptr);

}  // namespace fibscope
