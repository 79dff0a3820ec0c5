// MRtrix3 .tck writer (format in io/tck_format.h).
//
// The header is written first with a fixed-width zero-padded count field,
// so patching the count at finish() never moves the data. Streamlines are
// encoded chunk by chunk into a staging buffer and streamed to a temporary
// file that finish() renames into place. One-component per-point arrays go
// to sibling .tsf files "<stem>_<name>.tsf", written in step; what neither
// file can carry is dropped with one warning each.
#include <cctype>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>

#include "core/error.h"
#include "core/output_file.h"
#include "io/tck_format.h"
#include "io/tsf.h"
#include "io/writer.h"

namespace fibscope {
namespace {

constexpr size_t kFlushBytes = size_t(1) << 20;

// Array names become part of a file name: keep it portable.
std::string fileNamePart(const std::string& name) {
  std::string out;
  for (unsigned char c : name) out += (std::isalnum(c) || c == '-' || c == '_' || c == '.') ? char(c) : '_';
  return out.empty() ? "array" : out;
}

class TckWriter final : public TractogramWriter {
 public:
  TckWriter(const std::string& path, const TractogramHeader& like, const WriterOptions& options);
  void write(const Tractogram& chunk) override;
  void finish() override;

 private:
  struct TsfOutput {
    std::string array_name;
    std::unique_ptr<TsfWriter> writer;  // null once dropped
  };
  void writeTsf(TsfOutput& tsf, const Tractogram& chunk);

  std::string path_;
  TckDataType type_;
  std::unique_ptr<OutputFile> out_;
  uint64_t count_offset_ = 0;
  uint64_t streamlines_ = 0;
  std::vector<uint8_t> buffer_;
  std::vector<TsfOutput> tsf_;
  bool finished_ = false;
};

TckWriter::TckWriter(const std::string& path, const TractogramHeader& like, const WriterOptions& options)
    : path_(path) {
  const auto type = parseTckDataType(options.tck_datatype);
  if (!type)
    fail(path,
         "unknown tck datatype '" + options.tck_datatype + "' (expected Float32LE, Float32BE, Float64LE or Float64BE)");
  type_ = *type;

  for (const auto& a : like.per_streamline)
    warn("per-streamline array '" + a.name + "' dropped: .tck cannot store per-streamline data");
  std::vector<std::pair<std::string, std::string>> tsf_plan;  // array name, path
  const std::filesystem::path stem = std::filesystem::path(path).replace_extension();
  for (const auto& a : like.per_point) {
    if (a.components != 1) {
      warn("per-point array '" + a.name + "' (" + std::to_string(a.components) +
           " components) dropped: a .tsf holds one value per point");
      continue;
    }
    const std::string tsf_path = stem.string() + "_" + fileNamePart(a.name) + ".tsf";
    bool taken = false;
    for (const auto& [n, p] : tsf_plan) taken |= p == tsf_path;
    if (taken) {
      warn("per-point array '" + a.name + "' dropped: its file name " + tsf_path + " is taken by another array");
      continue;
    }
    tsf_plan.emplace_back(a.name, tsf_path);
  }
  if (!like.groups.empty()) {
    std::string names;
    for (const auto& g : like.groups) names += (names.empty() ? "" : ", ") + g.name;
    warn(std::to_string(like.groups.size()) + " groups dropped (.tck has no groups): " + names);
  }
  if (like.space.known) {
    const auto& d = like.space.dimensions;
    warn("voxel grid of the reference image (" + std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" +
         std::to_string(d[2]) + " voxels) dropped: .tck stores world coordinates only");
  }

  // Refuse before creating anything, so a refused write leaves no temp files.
  checkOverwrite(path, options.overwrite);
  for (const auto& [name, tsf_path] : tsf_plan) checkOverwrite(tsf_path, options.overwrite);

  std::vector<std::string> dropped;
  const TckHeaderText header = makeTckHeader(kTckMagic, like.properties, type_, &dropped);
  for (const auto& d : dropped) warn(d);
  out_ = std::make_unique<OutputFile>(path, options.overwrite);
  count_offset_ = header.count_offset;
  out_->write(header.text);
  for (const auto& [name, tsf_path] : tsf_plan)
    tsf_.push_back({name, std::make_unique<TsfWriter>(tsf_path, like.properties, type_, options.overwrite)});
}

void TckWriter::write(const Tractogram& chunk) {
  if (finished_) fail(path_, "internal error: write() after finish()");
  if (chunk.offsets.empty() || chunk.positions.size() != 3 * chunk.pointCount())
    fail(path_, "internal error: chunk positions do not match its offsets");
  const float kNaN = std::numeric_limits<float>::quiet_NaN();
  const float separator[3] = {kNaN, kNaN, kNaN};
  for (size_t i = 0; i < chunk.streamlineCount(); ++i) {
    const size_t n = chunk.pointsIn(i);
    const float* xyz = chunk.point(chunk.offsets[i]);
    const size_t bad = firstNonFinite(xyz, 3 * n);
    if (bad < 3 * n)
      fail(path_, "streamline " + std::to_string(streamlines_) + " point " + std::to_string(bad / 3) +
                      " has a non-finite coordinate (" + std::to_string(xyz[bad]) +
                      "); .tck cannot store it (NaN and Inf are its separators)");
    encodeSamples(xyz, 3 * n, type_, buffer_);
    encodeSamples(separator, 3, type_, buffer_);
    ++streamlines_;
    if (buffer_.size() >= kFlushBytes) {
      out_->write(buffer_.data(), buffer_.size());
      buffer_.clear();
    }
  }
  // An empty chunk carries no values, so it need not hold the header's arrays.
  if (chunk.streamlineCount() == 0) return;
  for (auto& tsf : tsf_)
    if (tsf.writer) writeTsf(tsf, chunk);
}

void TckWriter::writeTsf(TsfOutput& tsf, const Tractogram& chunk) {
  const DataArray* array = nullptr;
  for (const auto& a : chunk.per_point)
    if (a.name == tsf.array_name) array = &a;
  if (!array || array->components != 1 || array->values.size() != chunk.pointCount())
    fail(path_, "internal error: chunk lacks the one-component per-point array '" + tsf.array_name +
                    "' announced in the header, or its size is wrong");
  const size_t bad = firstNonFinite(array->values.data(), array->values.size());
  if (bad < array->values.size()) {
    // The .tck is still good: give up only this array (its temp file goes away).
    warn("per-point array '" + tsf.array_name + "' dropped: it holds " + std::to_string(array->values[bad]) +
         ", which a .tsf cannot store (NaN and Inf are its separators)");
    tsf.writer.reset();
    return;
  }
  for (size_t i = 0; i < chunk.streamlineCount(); ++i)
    tsf.writer->append(array->values.data() + chunk.offsets[i], chunk.pointsIn(i));
}

void TckWriter::finish() {
  if (finished_) fail(path_, "internal error: finish() called twice");
  finished_ = true;
  const float kInf = std::numeric_limits<float>::infinity();
  const float terminator[3] = {kInf, kInf, kInf};
  encodeSamples(terminator, 3, type_, buffer_);
  out_->write(buffer_.data(), buffer_.size());
  buffer_.clear();
  const std::string digits = formatTckCount(streamlines_);
  out_->writeAt(count_offset_, digits.data(), digits.size());
  // The .tck goes into place last: a failure before leaves no tractogram
  // that looks complete.
  for (auto& tsf : tsf_)
    if (tsf.writer) tsf.writer->finish();
  out_->commit();
}

}  // namespace

std::unique_ptr<TractogramWriter> createTckWriter(const std::string& path, const TractogramHeader& like,
                                                  const WriterOptions& options) {
  return std::make_unique<TckWriter>(path, like, options);
}

}  // namespace fibscope
