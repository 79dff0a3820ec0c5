// MRtrix3 .tck reader (format in io/tck_format.h), with optional .tsf files
// attached as per-point arrays.
//
// The header is parsed from a map of the file; the samples stream through
// one buffer (TrackDataStream). Each streamline is one vectorised scan for
// the next non-finite sample (its NaN separator) followed by one bulk copy
// of the points before it into the chunk, so the cost per point is a few
// instructions and resident memory stays bounded for any file size.
//
// Recoverable damage (tracking interrupted: wrong or missing count, no
// terminator, a partial last streamline) is read as far as it is whole and
// said in warnings(); damage inside the data (a triplet that is neither
// points nor a separator) throws Error with the byte offset.
#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/mapped_file.h"
#include "io/reader.h"
#include "io/tck_format.h"
#include "io/tsf.h"

namespace fibscope {
namespace {

const char* kindName(SampleKind kind) {
  switch (kind) {
    case SampleKind::kNaN:
      return "NaN";
    case SampleKind::kInf:
      return "Inf";
    case SampleKind::kFinite:
      break;
  }
  return "a number";
}

class TckReader final : public TractogramReader {
 public:
  TckReader(const std::string& path, const std::vector<std::string>& tsf_paths);

  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override { return at_end_ ? header_.file_bytes : data_->position(); }

 private:
  // Reads the next streamline into `chunk`; false once the data ended.
  bool readStreamline(Tractogram& chunk);
  // Makes a whole triplet available at the front; false at the end of data.
  bool fillTriplet() { return data_->fill(triplet_bytes_) >= triplet_bytes_; }
  // Ends reading: the warning for a truncated file, then the count and tsf checks.
  void endOfData(bool truncated);
  void warnFor(const std::string& path, const std::string& message) { warnings_.push_back(path + ": " + message); }

  std::unique_ptr<TrackDataStream> data_;
  TckDataType type_;
  size_t triplet_bytes_ = 12;
  uint64_t streamlines_ = 0;  // read so far
  bool has_count_line_ = false;
  int64_t header_count_ = -1;
  bool at_end_ = false;
  std::vector<std::unique_ptr<TsfReader>> tsf_;
};

TckReader::TckReader(const std::string& path, const std::vector<std::string>& tsf_paths) {
  TckHeaderInfo info;
  {
    const MappedFile file(path);
    info = parseTckHeader(file, kTckMagic);
    header_.file_bytes = file.size();
  }
  header_.path = path;
  header_.format = "tck";
  header_.properties = info.properties;
  for (const auto& w : info.warnings) warn(w);
  type_ = info.datatype;
  triplet_bytes_ = 3 * type_.bytes;
  data_ = std::make_unique<TrackDataStream>(path, info.data_offset, header_.file_bytes);
  has_count_line_ =
      std::any_of(info.properties.begin(), info.properties.end(), [](const auto& kv) { return kv.first == "count"; });
  header_count_ = info.count;
  if (header_count_ >= 0) {
    // Every streamline takes at least its separator triplet.
    const uint64_t data_bytes = header_.file_bytes - info.data_offset;
    const uint64_t most = data_bytes / triplet_bytes_;
    if (static_cast<uint64_t>(header_count_) <= most) {
      header_.declared_streamlines = header_count_;
    } else {
      warn("header count " + std::to_string(header_count_) + " is impossible: " + std::to_string(data_bytes) +
           " bytes of data hold at most " + std::to_string(most) + " streamlines");
    }
  }

  for (const auto& tsf_path : tsf_paths) {
    auto tsf = std::make_unique<TsfReader>(tsf_path);
    const std::string name = tsf->arrayName();
    for (const auto& a : header_.per_point)
      if (a.name == name) fail(tsf_path, "a second .tsf gives per-point array '" + name + "'; names must be unique");
    // MRtrix copies the tractogram's timestamp into every .tsf made from it.
    const std::string tck_stamp = header_.property("timestamp");
    std::string tsf_stamp;
    for (const auto& [k, v] : tsf->info().properties)
      if (k == "timestamp") tsf_stamp = v;
    if (!tck_stamp.empty() && !tsf_stamp.empty() && tck_stamp != tsf_stamp)
      warnFor(tsf_path, "timestamp " + tsf_stamp + " differs from the tractogram's " + tck_stamp +
                            "; it may have been made from another .tck");
    for (const auto& w : tsf->info().warnings) warnFor(tsf_path, w);
    header_.per_point.push_back({name, 1, tsf->info().datatype.arrayDtype(), {}});
    tsf_.push_back(std::move(tsf));
  }
}

bool TckReader::read(Tractogram& chunk, size_t max_points) {
  startChunk(chunk);
  if (at_end_) return false;
  max_points = std::max<size_t>(max_points, 1);
  // Bounded by what the file can still hold, so a lying file cannot make us
  // allocate. The streamline that crosses max_points ends the chunk past
  // it: a quarter more room keeps that last one (up to 65 k points at the
  // 2^18 points the encoder asks for) from reallocating and copying the
  // whole chunk, which was 4 % of `render`'s time on a 246 MB tckgen file.
  const uint64_t left = (data_->end() - data_->position()) / triplet_bytes_;
  const uint64_t room = uint64_t(max_points) + uint64_t(max_points) / 4;
  chunk.positions.reserve(3 * static_cast<size_t>(std::min<uint64_t>(left, room)));
  // A run of zero-length streamlines adds no points, so cap streamlines too.
  while (chunk.pointCount() < max_points && chunk.streamlineCount() < max_points) {
    if (!readStreamline(chunk)) break;
  }
  return chunk.streamlineCount() > 0;
}

bool TckReader::readStreamline(Tractogram& chunk) {
  const size_t s = type_.bytes;
  const size_t first_point = chunk.positions.size() / 3;
  uint64_t points = 0;  // of this streamline, already appended to the chunk
  // Points stream in buffer by buffer until the first non-finite sample.
  while (true) {
    if (!fillTriplet()) {
      // Tracking was interrupted: the last streamline has no separator (or
      // only part of one) and the Inf terminator never came.
      chunk.positions.resize(3 * first_point);
      const uint64_t end = data_->end();
      if (points == 0 && data_->available() == 0)
        warn("no terminator: file truncated at byte " + std::to_string(end) + " after " + std::to_string(streamlines_) +
             " complete streamlines");
      else
        warn("no terminator: file truncated at byte " + std::to_string(end) + ", last partial streamline of " +
             std::to_string(points) + " points dropped");
      endOfData(true);
      return false;
    }
    const size_t samples = data_->available() / s;
    const size_t hit = findNonFinite(data_->data(), samples, type_);
    const size_t whole = (hit == samples ? samples : hit) / 3;
    appendSamples(data_->data(), 3 * whole, type_, chunk.positions, header_.path, data_->position());
    points += whole;
    data_->consume(whole * triplet_bytes_);
    if (hit == samples) continue;
    if (hit % 3 == 0 && !fillTriplet()) continue;  // a separator cut short: reported above
    break;
  }

  // The front triplet holds the first non-finite sample.
  const uint64_t triplet = data_->position();
  const SampleKind kinds[3] = {
      classifySample(data_->data(), type_),
      data_->available() >= 2 * s ? classifySample(data_->data() + s, type_) : SampleKind::kFinite,
      data_->available() >= 3 * s ? classifySample(data_->data() + 2 * s, type_) : SampleKind::kFinite};
  if (kinds[0] == SampleKind::kFinite || kinds[0] != kinds[1] || kinds[1] != kinds[2]) {
    // A number next to NaN/Inf in one triplet never comes from a valid file cut short.
    std::string d;
    for (size_t c = 0; c < 3; ++c)
      d += std::string(c ? ", " : "") + (data_->available() >= (c + 1) * s ? kindName(kinds[c]) : "missing");
    failAt(header_.path, triplet,
           "streamline " + std::to_string(streamlines_) + " point " + std::to_string(points) + " is (" + d +
               "): NaN or Inf in only some coordinates (a separator is three NaNs, the terminator three Infs)");
  }
  data_->consume(triplet_bytes_);

  if (kinds[0] == SampleKind::kInf) {
    chunk.positions.resize(3 * first_point);
    if (points > 0)
      warn("streamline " + std::to_string(streamlines_) + " (" + std::to_string(points) +
           " points) has no NaN separator before the Inf terminator at byte " + std::to_string(triplet) + "; dropped");
    const uint64_t after = triplet + triplet_bytes_;
    if (after < data_->end())
      warn(std::to_string(data_->end() - after) + " bytes after the Inf terminator at byte " + std::to_string(triplet) +
           " ignored");
    endOfData(false);
    return false;
  }

  // A NaN triplet: the streamline is complete (it may have zero points).
  chunk.offsets.push_back(chunk.offsets.back() + points);
  for (size_t k = 0; k < tsf_.size(); ++k) tsf_[k]->readStreamline(streamlines_, points, chunk.per_point[k].values);
  ++streamlines_;
  return true;
}

void TckReader::endOfData(bool truncated) {
  at_end_ = true;
  if (const auto w = tckCountWarning(has_count_line_, header_count_, streamlines_)) warn(*w);
  for (const auto& tsf : tsf_) {
    switch (tsf->end()) {
      case TsfReader::End::kTerminated:
        break;
      case TsfReader::End::kPartialSample:
        warnFor(tsf->path(), "file ends inside a sample after its last streamline (truncated at byte " +
                                 std::to_string(tsf->bytesRead()) + "); the stray bytes are ignored");
        break;
      case TsfReader::End::kMoreStreamlines:
        // A truncated tractogram legitimately stops short of its scalars.
        if (truncated)
          warnFor(tsf->path(), "values beyond the " + std::to_string(streamlines_) +
                                   " streamlines read from the truncated tractogram ignored");
        else
          failAt(tsf->path(), tsf->bytesRead(),
                 "holds more streamlines than the " + std::to_string(streamlines_) + " of the tractogram");
    }
  }
}

}  // namespace

std::unique_ptr<TractogramReader> openTck(const std::string& path, const std::vector<std::string>& tsf_paths) {
  return std::make_unique<TckReader>(path, tsf_paths);
}

std::unique_ptr<TractogramReader> openTck(const std::string& path) { return openTck(path, {}); }

}  // namespace fibscope
