// .tsf track scalar files (MRtrix3): one value per point of a .tck.
//
// Same header and datatypes as .tck (io/tck_format.h) with the first line
// "mrtrix track scalars"; the samples are single values, a NaN after each
// streamline and an Inf at the end (which MRtrix's own tcksample leaves out). A .tsf means nothing without its .tck:
// its streamlines and points must match the tractogram one for one, so NaN
// and Inf can never be stored as values.
//
// To read: openTck(tck_path, {tsf paths}) in io/reader.h attaches each .tsf
// as a per-point array named after the file stem. To write: createTckWriter
// writes every one-component per-point array as "<stem>_<name>.tsf", or call
// writeTsf() / TsfWriter directly.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/mapped_file.h"
#include "core/output_file.h"
#include "core/tractogram.h"
#include "io/tck_format.h"
#include "io/writer.h"

namespace fibscope {

// Reads a .tsf one streamline at a time, in step with a tractogram reader.
// Safe on untrusted input: every disagreement with the tractogram throws
// Error naming this file, the byte offset and the streamline index.
class TsfReader {
 public:
  // Maps `path` and parses its header (throws Error like the .tck reader).
  explicit TsfReader(const std::string& path);

  const std::string& path() const { return path_; }
  const TckHeaderInfo& info() const { return info_; }
  // The per-point array name this file gives: its file name without ".tsf".
  std::string arrayName() const;

  // Appends the values of streamline `index`, which has `points` points in
  // the tractogram, to `values`.
  void readStreamline(uint64_t index, size_t points, std::vector<float>& values);

  enum class End { kTerminated, kPartialSample, kMoreStreamlines };
  // What follows the streamlines read so far: the Inf terminator or the end
  // of the file (MRtrix 3.0 tcksample writes no terminator), part of a
  // sample (a cut file), or more streamlines than the tractogram has.
  End end();

  // Bytes consumed so far (the position of the next sample).
  uint64_t bytesRead() const { return data_->position(); }

 private:
  std::string path_;
  TckHeaderInfo info_;
  std::unique_ptr<TrackDataStream> data_;
};

// Streams one value per point to a .tsf under a temporary name; finish()
// writes the terminator, patches the count and renames it into place.
class TsfWriter {
 public:
  // Throws Error if `path` exists and !overwrite. `properties` are copied to
  // the header as in a .tck (MRtrix matches a .tsf to its .tck by them);
  // unwritable keys are reported in `dropped`.
  TsfWriter(const std::string& path, const std::vector<std::pair<std::string, std::string>>& properties,
            const TckDataType& type, bool overwrite, std::vector<std::string>* dropped = nullptr);

  // Appends the `n` values of the next streamline. Throws Error if one is
  // NaN or Inf (they are the separators of the format).
  void append(const float* values, size_t n);
  void finish();

  const std::string& path() const { return out_.path(); }
  uint64_t streamlines() const { return streamlines_; }

 private:
  OutputFile out_;
  TckDataType type_;
  uint64_t count_offset_ = 0;
  uint64_t streamlines_ = 0;
  uint64_t points_ = 0;
  std::vector<uint8_t> buffer_;
  bool finished_ = false;
};

// Index of the first NaN or Inf among `n` floats, or `n`.
size_t firstNonFinite(const float* values, size_t n);

// Writes the one-component per-point array `array_name` of `tractogram` as a
// .tsf of `options.tck_datatype`, with the header properties of `like`.
// Throws Error if the array is missing, has several components or holds NaN
// or Inf, or if `path` exists and !options.overwrite.
void writeTsf(const std::string& path, const Tractogram& tractogram, const std::string& array_name,
              const TractogramHeader& like, const WriterOptions& options = {});

}  // namespace fibscope
