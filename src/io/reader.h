// Streaming tractogram readers.
//
// A reader hands out the streamlines of a file a chunk at a time, so a file
// of any size is read in bounded memory. Every reader is safe on untrusted
// input: anything malformed throws fibscope::Error with one line naming the
// file, the byte offset (or archive member) and what is wrong. Oddities that
// still allow reading (a tck whose `count` is wrong because tracking was
// interrupted) are appended to warnings() and reading goes on.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/tractogram.h"

namespace fibscope {

class TractogramReader {
 public:
  virtual ~TractogramReader() = default;

  const TractogramHeader& header() const { return header_; }

  // Clears `chunk` and fills it with the next streamlines, about
  // `max_points` points in all (at least one whole streamline, never a part
  // of one). Returns false when there are no more streamlines. Data array
  // names in `chunk` follow header().per_streamline / per_point.
  virtual bool read(Tractogram& chunk, size_t max_points = size_t(1) << 20) = 0;

  // Bytes of the file consumed so far (for progress bars).
  virtual uint64_t bytesRead() const = 0;

  const std::vector<std::string>& warnings() const { return warnings_; }

 protected:
  void warn(const std::string& message) { warnings_.push_back(oneLine(header_.path + ": " + message)); }
  // Empties `chunk` for the next read(): its data arrays follow the header's
  // (names, components, dtypes), keeping their capacity when they already do.
  void startChunk(Tractogram& chunk) const;
  TractogramHeader header_;
  std::vector<std::string> warnings_;
};

// Opens `path` by its extension (.tck, .trk, .trx or a TRX directory, .vtk, .vtp;
// .tsf is not a tractogram). Throws Error for unknown extensions and for
// headers that cannot be parsed.
std::unique_ptr<TractogramReader> openTractogram(const std::string& path);

// Reads every remaining streamline of `reader` into one tractogram whose
// data arrays follow the reader's header (small inputs, tests).
Tractogram readAllStreamlines(TractogramReader& reader);

// Reads a whole file into memory (small files, tests). Warnings are appended
// to `warnings` when given.
Tractogram readTractogram(const std::string& path, TractogramHeader* header = nullptr,
                          std::vector<std::string>* warnings = nullptr);

// Format-specific openers, for tests and for callers that know the format.
std::unique_ptr<TractogramReader> openTck(const std::string& path);
// A .tck with MRtrix track scalar files (.tsf) attached: each becomes a
// one-component per-point array named after its file stem ("fa.tsf" -> "fa").
// Their streamline and point counts must match the .tck (Error naming the
// .tsf, the byte offset and the streamline index otherwise).
std::unique_ptr<TractogramReader> openTck(const std::string& path, const std::vector<std::string>& tsf_paths);
std::unique_ptr<TractogramReader> openTrk(const std::string& path);
std::unique_ptr<TractogramReader> openTrx(const std::string& path);
std::unique_ptr<TractogramReader> openVtk(const std::string& path);
// VTK XML PolyData (.vtp): vtp_reader.cpp.
std::unique_ptr<TractogramReader> openVtp(const std::string& path);
// DSI Studio's TinyTrack .tt.gz (or an uncompressed .tt): tt_reader.cpp.
std::unique_ptr<TractogramReader> openTinyTrack(const std::string& path);

}  // namespace fibscope
