// Streaming tractogram writers.
//
// A writer is created with a header that announces the data arrays, takes
// chunks in order and writes the file under a temporary name; finish()
// completes the header (counts) and renames the file into place. A writer
// destroyed without finish() leaves no file behind. What the target format
// cannot carry (per-streamline data in tck, groups in trk, ...) is dropped
// and said once in warnings().
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/tractogram.h"

namespace fibscope {

struct WriterOptions {
  bool overwrite = false;          // --force
  // trx: "float16", "float32" or "float64" positions; zip or directory.
  std::string trx_position_dtype = "float32";
  bool trx_zip = true;             // false: write a TRX directory
  // tck: "Float32LE" (MRtrix default), "Float32BE", "Float64LE", "Float64BE".
  std::string tck_datatype = "Float32LE";
};

class TractogramWriter {
 public:
  virtual ~TractogramWriter() = default;
  // Appends the streamlines of `chunk` (its data arrays must match the header).
  virtual void write(const Tractogram& chunk) = 0;
  // Completes and renames the output. Must be called exactly once.
  virtual void finish() = 0;
  // Groups of the streamlines written (indices in the output), for outputs
  // whose groups are known only once the streamlines are (a filter's):
  // they replace the groups of the header the writer was made with. Call
  // before finish(). Formats without groups (tck, trk) drop them and warn.
  virtual void setGroups(std::vector<Group> groups) {
    if (!groups.empty()) warn(std::to_string(groups.size()) + " group(s) not written: the format has no groups");
  }
  // The groups of the header the writer was made with, renumbered for the
  // streamlines written (a filter's: each holds its kept members at their
  // output indices; a group left out is dropped). Unlike setGroups, the data
  // per group of the groups kept stays (it describes the group, not its
  // members). Call before finish(). Formats without groups ignore it (they
  // warned about the header's groups when made).
  virtual void renumberGroups(std::vector<Group> groups) { (void)groups; }
  const std::vector<std::string>& warnings() const { return warnings_; }

 protected:
  void warn(const std::string& message) { warnings_.push_back(oneLine(message)); }
  std::vector<std::string> warnings_;
};

// Creates a writer by the extension of `path` (.tck, .trk, .trx; a path
// ending in '/' or with trx_zip=false writes a TRX directory). `like` gives
// the data arrays, space (trk/trx voxel grid) and properties to carry over.
std::unique_ptr<TractogramWriter> createTractogramWriter(const std::string& path, const TractogramHeader& like,
                                                         const WriterOptions& options = {});

// Writes a whole tractogram (tests, small files). Data arrays are described
// by `like`, or by the tractogram itself when `like` names none.
void writeTractogram(const std::string& path, const Tractogram& tractogram, const TractogramHeader& like,
                     const WriterOptions& options = {}, std::vector<std::string>* warnings = nullptr);

std::unique_ptr<TractogramWriter> createTckWriter(const std::string& path, const TractogramHeader& like,
                                                  const WriterOptions& options);
std::unique_ptr<TractogramWriter> createTrkWriter(const std::string& path, const TractogramHeader& like,
                                                  const WriterOptions& options);
std::unique_ptr<TractogramWriter> createTrxWriter(const std::string& path, const TractogramHeader& like,
                                                  const WriterOptions& options);

}  // namespace fibscope
