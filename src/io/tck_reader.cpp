// MRtrix3 .tck reader (format in io/tck_format.h), with optional .tsf files
// attached as per-point arrays.
//
// The file is mapped and parsed in place. Each streamline is one scan for
// the next non-finite sample (its NaN separator) followed by one bulk copy
// of the points before it into the chunk, so the cost per point is a few
// instructions and the file is read at memory speed. Pages behind the
// reading position are handed back to the kernel as reading goes on.
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
    case SampleKind::kNaN: return "NaN";
    case SampleKind::kInf: return "Inf";
    case SampleKind::kFinite: break;
  }
  return "a number";
}

class TckReader final : public TractogramReader {
 public:
  TckReader(const std::string& path, const std::vector<std::string>& tsf_paths);

  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override { return pos_; }

 private:
  // Reads the streamline at pos_ into `chunk`; false once the data ended.
  bool readStreamline(Tractogram& chunk);
  // Ends reading: the warning for a truncated file, then the count and tsf checks.
  void endOfData(bool truncated);
  void prepareChunk(Tractogram& chunk) const;
  void warnFor(const std::string& path, const std::string& message) { warnings_.push_back(path + ": " + message); }

  MappedFile file_;
  TckDataType type_;
  uint64_t triplet_bytes_ = 12;
  uint64_t pos_ = 0;         // next byte to parse
  uint64_t released_ = 0;    // pages before this were handed back
  uint64_t streamlines_ = 0; // read so far
  bool has_count_line_ = false;
  int64_t header_count_ = -1;
  bool at_end_ = false;
  std::vector<std::unique_ptr<TsfReader>> tsf_;
};

TckReader::TckReader(const std::string& path, const std::vector<std::string>& tsf_paths) : file_(path) {
  const TckHeaderInfo info = parseTckHeader(file_, kTckMagic);
  header_.path = path;
  header_.format = "tck";
  header_.file_bytes = file_.size();
  header_.properties = info.properties;
  for (const auto& w : info.warnings) warn(w);
  type_ = info.datatype;
  triplet_bytes_ = 3 * type_.bytes;
  pos_ = info.data_offset;
  has_count_line_ = std::any_of(info.properties.begin(), info.properties.end(),
                                [](const auto& kv) { return kv.first == "count"; });
  header_count_ = info.count;
  if (header_count_ >= 0) {
    // Every streamline takes at least its separator triplet.
    const uint64_t most = (file_.size() - pos_) / triplet_bytes_;
    if (static_cast<uint64_t>(header_count_) <= most) {
      header_.declared_streamlines = header_count_;
    } else {
      warn("header count " + std::to_string(header_count_) + " is impossible: " +
           std::to_string(file_.size() - pos_) + " bytes of data hold at most " + std::to_string(most) +
           " streamlines");
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
  file_.adviseSequential();
}

void TckReader::prepareChunk(Tractogram& chunk) const {
  chunk.clear();
  chunk.per_streamline.clear();
  bool same = chunk.per_point.size() == header_.per_point.size();
  for (size_t i = 0; same && i < chunk.per_point.size(); ++i) same = chunk.per_point[i].name == header_.per_point[i].name;
  if (!same) chunk.per_point = header_.per_point;
}

bool TckReader::read(Tractogram& chunk, size_t max_points) {
  prepareChunk(chunk);
  if (at_end_) return false;
  max_points = std::max<size_t>(max_points, 1);
  // Bounded by what the file can still hold, so a lying file cannot make us allocate.
  const uint64_t left = (file_.size() - pos_) / triplet_bytes_;
  chunk.positions.reserve(3 * static_cast<size_t>(std::min<uint64_t>(left, max_points)));
  // A run of zero-length streamlines adds no points, so cap streamlines too.
  while (chunk.pointCount() < max_points && chunk.streamlineCount() < max_points) {
    if (!readStreamline(chunk)) break;
  }
  released_ = releaseConsumedPages(file_, released_, pos_);
  for (auto& tsf : tsf_) tsf->releaseConsumed();
  return chunk.streamlineCount() > 0;
}

bool TckReader::readStreamline(Tractogram& chunk) {
  const uint8_t* base = file_.data();
  const uint64_t end = file_.size();
  const uint64_t start = pos_;
  const size_t s = type_.bytes;
  const size_t available = static_cast<size_t>((end - start) / s);
  // The separator is the first non-finite sample; everything before it must
  // be whole finite points.
  const size_t hit = findNonFinite(base + start, available, type_);
  const uint64_t points = hit / 3;
  const uint64_t triplet = start + points * triplet_bytes_;

  const std::string where = "streamline " + std::to_string(streamlines_) + " point " + std::to_string(points);
  // Names what each coordinate of the triplet holds, for error messages.
  auto describe = [&] {
    std::string d = "(";
    for (size_t c = 0; c < 3; ++c) {
      const uint64_t at = triplet + c * s;
      d += c ? ", " : "";
      d += at + s <= end ? kindName(classifySample(base + at, type_)) : "missing";
    }
    return d + ")";
  };
  const std::string kMixed = ": NaN or Inf in only some coordinates (a separator is three NaNs, the terminator three Infs)";
  // A number followed by NaN/Inf in the same triplet never comes from a
  // valid file cut short.
  if (hit < available && hit % 3 != 0) failAt(header_.path, triplet, where + " is " + describe() + kMixed);

  if (hit == available || triplet + triplet_bytes_ > end) {
    // Tracking was interrupted: the last streamline has no separator (or
    // only part of one) and the Inf terminator never came.
    const uint64_t whole = (end - start) / triplet_bytes_;
    if (end == start)
      warn("no terminator: file truncated at byte " + std::to_string(end) + " after " + std::to_string(streamlines_) +
           " complete streamlines");
    else
      warn("no terminator: file truncated at byte " + std::to_string(end) + ", last partial streamline of " +
           std::to_string(std::min<uint64_t>(whole, points)) + " points dropped");
    endOfData(true);
    return false;
  }
  const SampleKind kinds[3] = {classifySample(base + triplet, type_), classifySample(base + triplet + s, type_),
                               classifySample(base + triplet + 2 * s, type_)};
  if (kinds[0] != kinds[1] || kinds[1] != kinds[2]) failAt(header_.path, triplet, where + " is " + describe() + kMixed);

  if (kinds[0] == SampleKind::kInf) {
    if (points > 0)
      warn("streamline " + std::to_string(streamlines_) + " (" + std::to_string(points) +
           " points) has no NaN separator before the Inf terminator at byte " + std::to_string(triplet) +
           "; dropped");
    const uint64_t after = triplet + triplet_bytes_;
    if (after < end)
      warn(std::to_string(end - after) + " bytes after the Inf terminator at byte " + std::to_string(triplet) +
           " ignored");
    endOfData(false);
    return false;
  }

  // A NaN triplet: the streamline is complete (it may have zero points).
  const size_t old = chunk.positions.size();
  chunk.positions.resize(old + 3 * points);
  decodeSamples(base + start, 3 * points, type_, chunk.positions.data() + old, header_.path, start);
  chunk.offsets.push_back(chunk.offsets.back() + points);
  for (size_t k = 0; k < tsf_.size(); ++k) tsf_[k]->readStreamline(streamlines_, points, chunk.per_point[k].values);
  ++streamlines_;
  pos_ = triplet + triplet_bytes_;
  return true;
}

void TckReader::endOfData(bool truncated) {
  at_end_ = true;
  pos_ = file_.size();
  const std::string holds = " the file holds " + std::to_string(streamlines_) + " streamlines";
  if (!has_count_line_)
    warn("header has no count;" + holds);
  else if (header_count_ >= 0 && static_cast<uint64_t>(header_count_) != streamlines_)
    warn("header says count " + std::to_string(header_count_) + " but" + holds);
  for (const auto& tsf : tsf_) {
    switch (tsf->end()) {
      case TsfReader::End::kTerminated: break;
      case TsfReader::End::kUnterminated:
        warnFor(tsf->path(), "no terminator after its last streamline (file truncated at byte " +
                                 std::to_string(tsf->bytesRead()) + ")");
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
