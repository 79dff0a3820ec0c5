// .fbl -> streamlines (see fbl_reader.h).
//
// The container is mapped; the reader keeps spans into the map (records,
// first-fiblet table, dps arrays) and a cursor on the next fiber. A chunk is
// filled fiber by fiber: the fiber's table entries and record flags are
// validated first (one byte per record), then its exact point count is
// allocated and the records are decoded into it. Nothing but the chunk is
// ever allocated per fiber, so memory is bounded for any file size.
#include "codec/fbl_reader.h"

#include <array>
#include <cstdio>
#include <span>
#include <string_view>
#include <unordered_set>

#include "codec/fbl_codec.h"
#include "codec/fbl_file.h"
#include "codec/fiblet_decoder.h"
#include "core/error.h"

namespace fibscope {
namespace {

// Untrusted names (section names, JSON strings) in one-line messages.
std::string quoted(std::string_view name) {
  std::string out = "'";
  for (const char ch : name) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7F && c != '\\' && c != '\'') {
      out += ch;
    } else {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\x%02x", c);
      out += buffer;
    }
  }
  return out + "'";
}

std::string str(uint64_t v) { return std::to_string(v); }

class FblReader final : public TractogramReader {
 public:
  FblReader(const std::string& path, DecodeOrder order);

  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override {
    if (fiber_ == fiber_count_) return header_.file_bytes;
    return fiblets_offset_ + first_fiblet_[fiber_] * record_bytes_;
  }

 private:
  // Checks the table entries and record flags of fiber `fiber_`, whose
  // fiblets are [first, last); returns its point count.
  uint64_t checkFiber(uint64_t first, uint64_t last) const;
  // Decodes fiblets [first, last) into `xyz` (room for exactly their points).
  void decodeFiber(uint64_t first, uint64_t last, float* xyz) const;
  [[noreturn]] void failIn(std::string_view section, const std::string& message) const {
    fail(header_.path, "section '" + std::string(section) + "': " + message);
  }
  const FblSection& requireSection(std::string_view name, FblDType dtype) const;

  FblFile file_;
  CodecParams params_;
  FibletDecoder decoder_;
  DecodeOrder order_;
  uint32_t n_ = 0;  // points per fiblet
  uint32_t record_bytes_ = 0;
  std::span<const uint8_t> records_;
  std::span<const uint64_t> first_fiblet_;   // fiber_count + 1 entries
  std::vector<std::span<const float>> dps_;  // parallel to header_.per_streamline
  std::vector<std::span<const float>> dpv_;  // parallel to header_.per_point
  std::span<const uint64_t> first_point_;    // fiber_count + 1 entries, with dpv sections only
  uint64_t fiber_count_ = 0;
  uint64_t fiblet_count_ = 0;
  uint64_t point_count_ = 0;  // the header's
  uint64_t fiblets_offset_ = 0;
  uint64_t fiber_ = 0;   // next fiber to read
  uint64_t points_ = 0;  // decoded so far
};

FblReader::FblReader(const std::string& path, DecodeOrder order)
    : file_(FblFile::open(path)),
      params_(codecParamsFromFbl(file_.header(), file_.path())),
      decoder_(params_),
      order_(order) {
  header_.path = file_.path();
  // Every checksum first: a flipped bit is then reported as corruption of
  // the part it hit, never as whatever structural error it happens to cause
  // later. One pass of hardware CRC-32C over the map, much cheaper than the
  // decode that follows.
  file_.verify();

  const FblHeaderFields& h = file_.header();
  n_ = params_.points_per_fiblet;
  record_bytes_ = params_.recordBytes();
  fiber_count_ = h.fiber_count;
  fiblet_count_ = h.fiblet_count;
  point_count_ = h.point_count;

  const FblSection& fiblets = requireSection(kFblSectionFiblets, FblDType::kUint32);
  const auto words = file_.array<uint32_t>(fiblets);
  // FblFile::open checked bytes = fiblet_count * fiblet_record_bytes, and
  // codecParamsFromFbl that the record size is the one of N.
  records_ = {reinterpret_cast<const uint8_t*>(words.data()), words.size() * 4};
  fiblets_offset_ = fiblets.offset;
  // Each fiblet holds 1..N points (fiblet_count * N cannot overflow: the
  // records are in the file).
  if (point_count_ < fiblet_count_ || point_count_ > fiblet_count_ * n_)
    fail(header_.path, "header: " + str(point_count_) + " points cannot be held by " + str(fiblet_count_) +
                           " fiblets of 1 to " + str(n_) + " points");

  const FblSection& table = requireSection(kFblSectionFiberFirstFiblet, FblDType::kUint64);
  first_fiblet_ = file_.array<uint64_t>(table);  // fiber_count + 1 entries (FblFile::open)
  if (first_fiblet_.front() != 0)
    failIn(kFblSectionFiberFirstFiblet, "fiber 0 starts at fiblet " + str(first_fiblet_.front()) + ", expected 0");
  if (first_fiblet_.back() != fiblet_count_)
    failIn(kFblSectionFiberFirstFiblet, "last entry " + str(first_fiblet_.back()) + ", expected the fiblet count " +
                                            str(fiblet_count_) + " (header)");

  const FblSection& source = requireSection(kFblSectionSource, FblDType::kUtf8);
  const auto text = file_.data(source);
  TractogramHeader original =
      headerFromFblSource(std::string_view(reinterpret_cast<const char*>(text.data()), text.size()), header_.path);
  header_.format = std::move(original.format);
  header_.space = std::move(original.space);
  header_.properties = std::move(original.properties);
  header_.per_streamline = std::move(original.per_streamline);
  header_.per_point = std::move(original.per_point);
  header_.file_bytes = file_.fileBytes();
  // Both fit: the table has fiber_count + 1 entries of 8 bytes in the file,
  // and point_count <= 60 * fiblet_count was checked above.
  header_.declared_streamlines = int64_t(fiber_count_);
  header_.declared_points = int64_t(point_count_);

  // The source JSON and the dps sections must describe the same arrays.
  std::unordered_set<std::string> listed;
  for (const DataArray& a : header_.per_streamline) {
    const std::string name = std::string(kFblSectionDpsPrefix) + a.name;
    if (!listed.insert(name).second)
      failIn(kFblSectionSource, "per-streamline array " + quoted(a.name) + " listed twice");
    const FblSection* s = file_.find(name);
    if (!s) failIn(kFblSectionSource, "per-streamline array " + quoted(a.name) + " has no section " + quoted(name));
    if (s->components != a.components)
      fail(header_.path, "section " + quoted(name) + ": " + str(s->components) + " components, the source JSON says " +
                             str(a.components));
    // Element count = fiber count was checked by FblFile::open; array<float>
    // checks the dtype.
    dps_.push_back(file_.array<float>(*s));
  }
  for (const FblSection& s : file_.sections())
    if (std::string_view(s.name).starts_with(kFblSectionDpsPrefix) && !listed.contains(s.name))
      fail(header_.path, "section " + quoted(s.name) + " is not among the per-streamline arrays of the source JSON");

  // Likewise the per-point arrays, and their table of first points (its
  // entries are checked against the decoded counts fiber by fiber).
  for (const DataArray& a : header_.per_point) {
    const std::string name = std::string(kFblSectionDpvPrefix) + a.name;
    if (!listed.insert(name).second) failIn(kFblSectionSource, "per-point array " + quoted(a.name) + " listed twice");
    const FblSection* s = file_.find(name);
    if (!s) failIn(kFblSectionSource, "per-point array " + quoted(a.name) + " has no section " + quoted(name));
    if (s->components != a.components)
      fail(header_.path, "section " + quoted(name) + ": " + str(s->components) + " components, the source JSON says " +
                             str(a.components));
    dpv_.push_back(file_.array<float>(*s));  // one element per point: FblFile::open
  }
  for (const FblSection& s : file_.sections())
    if (std::string_view(s.name).starts_with(kFblSectionDpvPrefix) && !listed.contains(s.name))
      fail(header_.path, "section " + quoted(s.name) + " is not among the per-point arrays of the source JSON");
  if (!dpv_.empty()) {
    first_point_ = file_.array<uint64_t>(requireSection(kFblSectionFiberFirstPoint, FblDType::kUint64));
    if (first_point_.back() != point_count_)
      failIn(kFblSectionFiberFirstPoint,
             "last entry " + str(first_point_.back()) + ", expected the point count " + str(point_count_) + " (header)");
  }
}

const FblSection& FblReader::requireSection(std::string_view name, FblDType dtype) const {
  const FblSection* s = file_.find(name);
  if (!s) fail(header_.path, "no section '" + std::string(name) + "' (a .fbl tractogram needs it)");
  if (s->dtype != dtype) failIn(name, "holds " + fblDTypeName(s->dtype) + ", expected " + fblDTypeName(dtype));
  if (s->components != 1) failIn(name, str(s->components) + " components, expected 1");
  return *s;
}

uint64_t FblReader::checkFiber(uint64_t first, uint64_t last) const {
  const std::string fiber = "fiber " + str(fiber_);
  // `first` is known to be <= fiblet_count (the previous fiber's end, or 0).
  if (last < first)
    failIn(kFblSectionFiberFirstFiblet, fiber + " starts at fiblet " + str(first) + " but fiber " + str(fiber_ + 1) +
                                            " at fiblet " + str(last) + " (the table must not decrease)");
  if (last > fiblet_count_)
    failIn(kFblSectionFiberFirstFiblet,
           fiber + " ends at fiblet " + str(last) + ", past the " + str(fiblet_count_) + " fiblets");
  if (last - first > kFblMaxFiberPoints)
    failIn(kFblSectionFiberFirstFiblet, fiber + " has " + str(last - first) + " fiblets, more than the " +
                                            str(kFblMaxFiberPoints) + " points a fiber may have");
  const uint32_t flags_byte = shader::fibletFlagsByte(n_);
  uint64_t points = 0;
  for (uint64_t i = first; i < last; ++i) {
    const uint32_t flags = records_[i * record_bytes_ + flags_byte];
    const uint32_t count = shader::fibletCount(flags);
    const auto where = [&] {
      return "fiblet " + str(i) + " (" + fiber + ", fiblets " + str(first) + ".." + str(last - 1) + "): ";
    };
    if (count < 1 || count > n_)
      failIn(kFblSectionFiblets, where() + "point count " + str(count) + " outside [1, " + str(n_) + "]");
    const bool begins = (flags & shader::kFibletFlagBegins) != 0;
    const bool ends = (flags & shader::kFibletFlagEnds) != 0;
    if (begins != (i == first))
      failIn(kFblSectionFiblets, where() + (begins ? "begins-fiber flag set on a fiblet that is not the fiber's first"
                                                   : "begins-fiber flag missing on the fiber's first fiblet"));
    if (ends != (i + 1 == last))
      failIn(kFblSectionFiblets, where() + (ends ? "ends-fiber flag set on a fiblet that is not the fiber's last"
                                                 : "ends-fiber flag missing on the fiber's last fiblet"));
    points += count;
  }
  if (points > kFblMaxFiberPoints)
    failIn(kFblSectionFiblets,
           fiber + " has " + str(points) + " points, more than the " + str(kFblMaxFiberPoints) + " a fiber may have");
  return points;
}

void FblReader::decodeFiber(uint64_t first, uint64_t last, float* out) const {
  std::array<float, 3 * shader::kFibletMaxPoints> xyz;
  for (uint64_t i = first; i < last; ++i) {
    // checkFiber validated the count, so decode returns it (never 0).
    const uint32_t count = decoder_.decode(records_.data() + i * record_bytes_, xyz.data(), order_);
    for (uint32_t k = 0; k < count; ++k) {
      // As FibletDecoder::decodeAll: world mm in double, rounded to float.
      const auto w = decoder_.toWorld(&xyz[3 * k]);
      for (int c = 0; c < 3; ++c) *out++ = float(w[c]);
    }
  }
}

bool FblReader::read(Tractogram& chunk, size_t max_points) {
  startChunk(chunk);
  if (fiber_ == fiber_count_) return false;
  const uint64_t first_fiber = fiber_;
  uint64_t points = 0;
  do {
    const uint64_t first = first_fiblet_[fiber_];
    const uint64_t last = first_fiblet_[fiber_ + 1];
    const uint64_t n = checkFiber(first, last);
    if (n > point_count_ - points_)
      fail(header_.path,
           "header: " + str(point_count_) + " points, but fibers 0.." + str(fiber_) + " hold " + str(points_ + n));
    if (!first_point_.empty() && (first_point_[fiber_] != points_ || first_point_[fiber_ + 1] != points_ + n))
      failIn(kFblSectionFiberFirstPoint, "fiber " + str(fiber_) + " spans points " + str(first_point_[fiber_]) + ".." +
                                             str(first_point_[fiber_ + 1]) + ", but its fiblets hold points " +
                                             str(points_) + ".." + str(points_ + n));
    const size_t at = chunk.positions.size();
    chunk.positions.resize(at + 3 * size_t(n));
    decodeFiber(first, last, chunk.positions.data() + at);
    chunk.offsets.push_back(chunk.offsets.back() + n);
    points += n;
    points_ += n;
    ++fiber_;
  } while (fiber_ < fiber_count_ && points < max_points);

  for (size_t a = 0; a < dps_.size(); ++a) {
    const size_t k = header_.per_streamline[a].components;
    chunk.per_streamline[a].values.assign(dps_[a].begin() + first_fiber * k, dps_[a].begin() + fiber_ * k);
  }
  // points_ <= point_count_ (checked per fiber above), the arrays' length.
  for (size_t a = 0; a < dpv_.size(); ++a) {
    const size_t k = header_.per_point[a].components;
    chunk.per_point[a].values.assign(dpv_[a].begin() + (points_ - points) * k, dpv_[a].begin() + points_ * k);
  }
  if (fiber_ == fiber_count_ && points_ != point_count_)
    fail(header_.path, "header: " + str(point_count_) + " points, but the fibers hold " + str(points_));
  return true;
}

}  // namespace

std::unique_ptr<TractogramReader> openFbl(const std::string& path, DecodeOrder order) {
  return std::make_unique<FblReader>(path, order);
}

}  // namespace fibscope
