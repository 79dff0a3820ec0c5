#include "io/tsf.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/error.h"

namespace fibscope {
namespace {

// Output is handed to OutputFile in pieces of about this size.
constexpr size_t kFlushBytes = size_t(1) << 20;

std::string indexText(uint64_t index) { return "streamline " + std::to_string(index); }

}  // namespace

TsfReader::TsfReader(const std::string& path) : path_(path) {
  uint64_t file_bytes = 0;
  {
    const MappedFile file(path);
    info_ = parseTckHeader(file, kTsfMagic);
    file_bytes = file.size();
  }
  data_ = std::make_unique<TrackDataStream>(path, info_.data_offset, file_bytes);
}

std::string TsfReader::arrayName() const {
  std::filesystem::path p(path());
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".tsf" ? p.stem().string() : p.filename().string();
}

void TsfReader::readStreamline(uint64_t index, size_t points, std::vector<float>& values) {
  const TckDataType& type = info_.datatype;
  const size_t s = type.bytes;
  const std::string tck_side = " (the tractogram's streamline has " + std::to_string(points) + " points)";
  size_t got = 0;  // values of this streamline appended so far
  // The values then their NaN separator, buffer by buffer.
  while (true) {
    if (data_->fill(s) < s)
      failAt(path(), data_->end(),
             "file truncated inside " + indexText(index) + " after " + std::to_string(got) + " values" + tck_side);
    const size_t wanted = points - got + 1;
    const size_t scanned = std::min(data_->available() / s, wanted);
    const size_t hit = findNonFinite(data_->data(), scanned, type);
    const size_t finite = std::min(hit, points - got);
    appendSamples(data_->data(), finite, type, values, path(), data_->position());
    got += finite;
    data_->consume(finite * s);
    if (hit == scanned && scanned < wanted) continue;  // more values in the next buffer
    break;
  }
  // The front sample should be the separator.
  const SampleKind kind = classifySample(data_->data(), type);
  if (kind == SampleKind::kFinite)
    failAt(path(), data_->position(), indexText(index) + " has more values than points" + tck_side);
  if (got < points) {
    if (kind == SampleKind::kInf)
      failAt(path(), data_->position(),
             "the file ends after " + std::to_string(index) + " streamlines, but the tractogram has more (" +
                 indexText(index) + " has " + std::to_string(points) + " points)");
    failAt(path(), data_->position(), indexText(index) + " has " + std::to_string(got) + " values" + tck_side);
  }
  if (kind == SampleKind::kInf)
    failAt(path(), data_->position(),
           indexText(index) + " is followed by the Inf terminator instead of a NaN separator" + tck_side);
  data_->consume(s);
}

TsfReader::End TsfReader::end() {
  const size_t left = data_->fill(info_.datatype.bytes);
  if (left == 0) return End::kTerminated;
  if (left < info_.datatype.bytes) return End::kPartialSample;
  return classifySample(data_->data(), info_.datatype) == SampleKind::kInf ? End::kTerminated : End::kMoreStreamlines;
}

size_t firstNonFinite(const float* values, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!std::isfinite(values[i])) return i;
  return n;
}

TsfWriter::TsfWriter(const std::string& path, const std::vector<std::pair<std::string, std::string>>& properties,
                     const TckDataType& type, bool overwrite, std::vector<std::string>* dropped)
    : out_(path, overwrite), type_(type) {
  const TckHeaderText header = makeTckHeader(kTsfMagic, properties, type, dropped);
  count_offset_ = header.count_offset;
  out_.write(header.text);
}

void TsfWriter::append(const float* values, size_t n) {
  if (finished_) fail(path(), "internal error: tsf write after finish()");
  const size_t bad = firstNonFinite(values, n);
  if (bad < n)
    fail(path(), "streamline " + std::to_string(streamlines_) + " point " + std::to_string(bad) + " has value " +
                     std::to_string(values[bad]) + ", which a .tsf cannot store (NaN and Inf are its separators)");
  encodeSamples(values, n, type_, buffer_);
  encodeRepeated(std::numeric_limits<float>::quiet_NaN(), 1, type_, buffer_);
  ++streamlines_;
  points_ += n;
  if (buffer_.size() >= kFlushBytes) {
    out_.write(buffer_.data(), buffer_.size());
    buffer_.clear();
  }
}

void TsfWriter::finish() {
  if (finished_) fail(path(), "internal error: tsf finish() called twice");
  encodeRepeated(std::numeric_limits<float>::infinity(), 1, type_, buffer_);
  out_.write(buffer_.data(), buffer_.size());
  buffer_.clear();
  const std::string digits = formatTckCount(streamlines_);
  out_.writeAt(count_offset_, digits.data(), digits.size());
  out_.commit();
  finished_ = true;
}

void writeTsf(const std::string& path, const Tractogram& tractogram, const std::string& array_name,
              const TractogramHeader& like, const WriterOptions& options) {
  const auto type = parseTckDataType(options.tck_datatype);
  if (!type) fail(path, "unknown tck datatype '" + options.tck_datatype + "'");
  const DataArray* array = nullptr;
  for (const auto& a : tractogram.per_point)
    if (a.name == array_name) array = &a;
  if (!array) fail(path, "the tractogram has no per-point array '" + array_name + "'");
  if (array->components != 1)
    fail(path, "per-point array '" + array_name + "' has " + std::to_string(array->components) +
                   " components; a .tsf holds one value per point");
  if (array->values.size() != tractogram.pointCount())
    fail(path, "per-point array '" + array_name + "' has " + std::to_string(array->values.size()) + " values for " +
                   std::to_string(tractogram.pointCount()) + " points");
  TsfWriter writer(path, like.properties, *type, options.overwrite);
  for (size_t i = 0; i < tractogram.streamlineCount(); ++i)
    writer.append(array->values.data() + tractogram.offsets[i], tractogram.pointsIn(i));
  writer.finish();
}

}  // namespace fibscope
