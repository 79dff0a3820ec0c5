// `fibscope compress`: a tractogram of any size -> .fbl, streamed in two
// passes over the input with bounded memory (DESIGN.md section 5).
//
//   pass 1 (analyse): the exact bounding box, the exact largest turn, and a
//          bounded sample of steps and turns -> CodecParams.
//   pass 2 (encode):  chunks of whole fibers are encoded on a pool of
//          worker threads (one FibletEncoder and error meter each); the
//          main thread reads ahead and writes the results in input order:
//          fiblet records straight into the .fbl's "fiblets" section, the
//          per-fiber tables into scratch files that become the sections
//          after it. At most threads + 2 chunks are in memory at once.
// The output is written under a temporary name and renamed at the end
// (FblWriter), so a failure leaves nothing behind.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "codec/codec_error.h"
#include "codec/codec_params.h"
#include "codec/fiblet_encoder.h"
#include "core/progress.h"
#include "io/reader.h"

namespace fibscope {

struct CompressOptions {
  EncodeOptions encode;
  CodecParamOptions params;
  // Resample every fiber to the step delta along its arc length before
  // encoding (for inputs whose steps vary: resampled or compressed files).
  bool resample = false;
  unsigned threads = 0;  // encoding threads; 0 = one per core
  // Points per chunk handed to a worker. Small enough that the few chunks
  // in flight touch little fresh memory (first touches of pages cost ~5 us
  // each on the VMs measured), large enough to amortise the hand-over.
  size_t chunk_points = size_t(1) << 18;
  bool overwrite = false;
  bool terminal_progress = true;  // progress bars on stderr (when a terminal)
  Progress::Sink progress_sink;   // and/or to the viewer
};

struct CompressReport {
  std::string input, output, input_format;
  uint64_t input_bytes = 0;   // the input file (or TRX directory) size
  uint64_t output_bytes = 0;  // the whole .fbl
  uint64_t fiblet_bytes = 0;  // the "fiblets" section
  uint64_t fibers = 0, points = 0, fiblets = 0;
  CodecParamSummary analysis;  // includes the parameters used
  EncodeMode mode = EncodeMode::ClosedLoop;
  unsigned threads = 1;
  EncodeReport encode;    // exceptions: splits, short fibers, clamped points
  CodecErrorStats error;  // decoded points against the encoded ones, um
  bool resampled = false;
  ResampleReport resample;            // what resampling moved, when resampled
  std::vector<std::string> dropped;   // input data not stored (per-point arrays, groups, ...)
  std::vector<std::string> warnings;  // reader warnings and the encoder's advice
  double analyse_seconds = 0, encode_seconds = 0;

  double bytesPerPoint() const { return points ? double(output_bytes) / double(points) : 0.0; }
  double ratio() const { return output_bytes ? double(input_bytes) / double(output_bytes) : 0.0; }
  double seconds() const { return analyse_seconds + encode_seconds; }
  double pointsPerSecond() const { return seconds() > 0 ? double(points) / seconds() : 0.0; }
};

// Opens the input afresh for each pass.
using ReaderFactory = std::function<std::unique_ptr<TractogramReader>()>;

// Throws Error (one line, naming the file) on bad input or parameters, and
// when the output exists and !options.overwrite.
CompressReport compressTractogram(const ReaderFactory& open_input, const std::string& output,
                                  const CompressOptions& options = {});

}  // namespace fibscope
