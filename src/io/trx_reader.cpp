// TRX reader (tee-ar-ex, https://github.com/tee-ar-ex/trx-spec).
//
// Opening reads header.json, checks every member's byte size against the
// counts it declares, reads the offsets whole (8 bytes per streamline) and
// the groups. Positions, dpv and dps are then streamed a chunk at a time:
// stored zip members and directory files straight out of a memory map,
// compressed members inflated sequentially by libzip. Positions are already
// RAS+ millimetres, so they are only converted to float.
//
// Offsets: the current spec ends the array with a sentinel equal to
// NB_VERTICES (NB_STREAMLINES + 1 values); files from before that change
// hold NB_STREAMLINES values. Both are accepted.
#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/reader.h"
#include "io/trx_format.h"

namespace fibscope {
namespace {

// header.json is a handful of keys; anything this large is not a header.
constexpr uint64_t kMaxHeaderBytes = uint64_t(16) << 20;
// Data per group is a few values per group; larger members are skipped.
constexpr uint64_t kMaxDpgBytes = uint64_t(1) << 20;
// Counts above 2^53 cannot come from a real file (and are not exact in JSON).
constexpr uint64_t kMaxCount = uint64_t(1) << 53;
// Values decoded per step. Vectors grow as data actually arrives, so a
// compressed member that claims more than it holds costs no allocation.
constexpr size_t kDecodeStep = size_t(1) << 20;

std::string oneLine(std::string s) {
  std::replace_if(s.begin(), s.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  return s;
}

std::string shortDump(const nlohmann::json& value) {
  std::string text = oneLine(value.dump());
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

// Deepest nesting of JSON arrays and objects in `text` (brackets inside
// strings do not count). Checked before parsing: serialising a value back
// (dump()) recurses once per level.
size_t jsonNesting(std::string_view text) {
  size_t depth = 0;
  size_t deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

std::vector<std::string_view> splitPath(std::string_view name) {
  std::vector<std::string_view> parts;
  size_t start = 0;
  while (true) {
    const size_t slash = name.find('/', start);
    parts.push_back(name.substr(start, slash - start));
    if (slash == std::string_view::npos) break;
    start = slash + 1;
  }
  return parts;
}

struct ArrayStream {
  const trx::Member* member = nullptr;
  trx::MemberName name;
  std::unique_ptr<trx::MemberReader> reader;
};

class TrxReader final : public TractogramReader {
 public:
  explicit TrxReader(const std::string& path);
  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override;

 private:
  [[noreturn]] void failMember(const std::string& member, const std::string& message) const {
    fail(header_.path, "member " + member + ": " + message);
  }
  void parseHeader();
  void classifyMembers();
  void checkSize(const trx::Member& member, uint64_t count, const char* count_name, uint32_t components,
                 trx::DType dtype) const;
  void readOffsets(const trx::Member& member, trx::DType dtype);
  void readGroup(const trx::Member& member, const trx::MemberName& name);
  void readDataPerGroup(const trx::Member& member, const std::string& group, const std::string& file_name);
  void appendValues(ArrayStream& stream, uint64_t count, std::vector<float>& out);

  trx::Archive archive_;
  uint64_t nb_streamlines_ = 0;
  uint64_t nb_vertices_ = 0;
  std::vector<uint64_t> offsets_;  // NB_STREAMLINES + 1 values, the last NB_VERTICES
  ArrayStream positions_;
  std::vector<ArrayStream> per_streamline_;
  std::vector<ArrayStream> per_point_;
  uint64_t next_streamline_ = 0;
  uint64_t fixed_bytes_read_ = 0;  // header, offsets, groups: read while opening
};

TrxReader::TrxReader(const std::string& path) : archive_(path) {
  header_.path = path;
  header_.format = "trx";
  header_.file_bytes = archive_.fileBytes();
  for (const std::string& note : archive_.notes()) warn(note);
  parseHeader();
  classifyMembers();
}

void TrxReader::parseHeader() {
  const trx::Member* member = archive_.find("header.json");
  if (!member) fail(header_.path, "missing member header.json (not a TRX file?)");
  const std::string text = archive_.readWhole(*member, kMaxHeaderBytes);
  fixed_bytes_read_ += member->stored_size;

  constexpr size_t kMaxNesting = 64;
  if (jsonNesting(text) > kMaxNesting)
    failMember("header.json", "JSON nests deeper than " + std::to_string(kMaxNesting) + " levels");
  nlohmann::json header;
  try {
    header = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    failMember("header.json", "byte " + std::to_string(e.byte) + ": invalid JSON (" + oneLine(e.what()) + ")");
  } catch (const nlohmann::json::exception& e) {
    // Not only syntax: a number beyond double's range (1e999) is
    // out_of_range.406, which escaped as a crash before.
    failMember("header.json", "invalid JSON (" + oneLine(e.what()) + ")");
  }
  if (!header.is_object()) failMember("header.json", std::string("expected a JSON object, found ") + header.type_name());

  auto find = [&](const char* key) -> const nlohmann::json& {
    const auto it = header.find(key);
    if (it == header.end()) failMember("header.json", std::string("missing key ") + key);
    return *it;
  };
  // A count: a non-negative integer (an integral float such as 12.0 is accepted).
  auto count = [&](const char* key, const nlohmann::json& value) -> uint64_t {
    if (value.is_number_unsigned() && value.get<uint64_t>() <= kMaxCount) return value.get<uint64_t>();
    if (value.is_number_float()) {
      const double v = value.get<double>();
      if (v >= 0 && v <= static_cast<double>(kMaxCount) && std::floor(v) == v) return static_cast<uint64_t>(v);
    }
    failMember("header.json", std::string(key) + " must be an integer in 0..2^53, found " + shortDump(value));
  };

  nb_streamlines_ = count("NB_STREAMLINES", find("NB_STREAMLINES"));
  nb_vertices_ = count("NB_VERTICES", find("NB_VERTICES"));

  // VOXEL_TO_RASMM: 4 lists of 4 numbers (a flat list of 16 is accepted too).
  const nlohmann::json& affine = find("VOXEL_TO_RASMM");
  std::vector<double> values;
  if (affine.is_array() && affine.size() == 4) {
    for (const auto& row : affine) {
      if (!row.is_array() || row.size() != 4) break;
      for (const auto& v : row) values.push_back(v.is_number() ? v.get<double>() : NAN);
    }
  } else if (affine.is_array() && affine.size() == 16) {
    for (const auto& v : affine) values.push_back(v.is_number() ? v.get<double>() : NAN);
  }
  if (values.size() != 16 || !std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); }))
    failMember("header.json", "VOXEL_TO_RASMM must be 4 lists of 4 finite numbers, found " + shortDump(affine));

  // DIMENSIONS: 3 non-negative integers (uint16 in the spec; integral floats accepted).
  const nlohmann::json& dimensions = find("DIMENSIONS");
  auto dimension = [](const nlohmann::json& v) -> int64_t {
    const double d = v.is_number() ? v.get<double>() : -1.0;
    return d >= 0 && d <= std::numeric_limits<int32_t>::max() && std::floor(d) == d ? static_cast<int64_t>(d) : -1;
  };
  if (!dimensions.is_array() || dimensions.size() != 3 ||
      !std::all_of(dimensions.begin(), dimensions.end(), [&](const nlohmann::json& v) { return dimension(v) >= 0; }))
    failMember("header.json", "DIMENSIONS must be a list of 3 non-negative integers, found " + shortDump(dimensions));

  Space& space = header_.space;
  space.known = true;
  for (size_t i = 0; i < 16; ++i) space.voxel_to_rasmm[i] = static_cast<float>(values[i]);
  space.voxel_order.clear();
  for (size_t axis = 0; axis < 3; ++axis) {
    space.dimensions[axis] = static_cast<int32_t>(dimension(dimensions[axis]));
    // Voxel size: length of the axis' column; orientation: the world axis it
    // points along most (as nibabel's aff2axcodes).
    double norm2 = 0;
    size_t major = 0;
    for (size_t row = 0; row < 3; ++row) {
      const double a = values[row * 4 + axis];
      norm2 += a * a;
      if (std::abs(a) > std::abs(values[major * 4 + axis])) major = row;
    }
    space.voxel_sizes[axis] = static_cast<float>(std::sqrt(norm2));
    const double a = values[major * 4 + axis];
    space.voxel_order += a > 0 ? "RAS"[major] : a < 0 ? "LPI"[major] : '?';
  }

  header_.declared_streamlines = static_cast<int64_t>(nb_streamlines_);
  header_.declared_points = static_cast<int64_t>(nb_vertices_);
  // Other keys are kept, as JSON text, for a TRX writer to put back.
  for (const auto& [key, value] : header.items()) {
    if (key == "NB_STREAMLINES" || key == "NB_VERTICES" || key == "VOXEL_TO_RASMM" || key == "DIMENSIONS") continue;
    header_.properties.emplace_back(key, value.dump());
  }
}

void TrxReader::checkSize(const trx::Member& member, uint64_t count, const char* count_name, uint32_t components,
                          trx::DType dtype) const {
  uint64_t values = 0;
  uint64_t expected = 0;
  const bool overflow = __builtin_mul_overflow(count, uint64_t(components), &values) ||
                        __builtin_mul_overflow(values, uint64_t(trx::dtypeSize(dtype)), &expected);
  if (!overflow && member.size == expected) return;
  failMember(member.name, "holds " + std::to_string(member.size) + " bytes, expected " +
                              (overflow ? std::string("more than 2^64") : std::to_string(expected)) + " (" +
                              count_name + " " + std::to_string(count) + " x " + std::to_string(components) +
                              " components x " + std::to_string(trx::dtypeSize(dtype)) + " bytes)");
}

void TrxReader::classifyMembers() {
  const trx::Member* offsets_member = nullptr;
  trx::DType offsets_dtype = trx::DType::kUint64;
  std::vector<const trx::Member*> group_members;
  std::vector<trx::MemberName> group_names;
  std::vector<const trx::Member*> dpg_members;

  for (const trx::Member& member : archive_.members()) {
    if (member.name == "header.json") continue;
    const std::vector<std::string_view> parts = splitPath(member.name);
    const std::string file_name(parts.back());
    std::string why;
    const auto parsed = trx::parseMemberName(file_name, &why);
    const std::string folder(parts.size() > 1 ? parts[0] : std::string_view());

    if (parts.size() == 1) {
      const bool is_positions = file_name.rfind("positions.", 0) == 0;
      const bool is_offsets = file_name.rfind("offsets.", 0) == 0;
      if (!is_positions && !is_offsets) {
        warn("ignored member " + member.name + " (not part of the TRX layout)");
        continue;
      }
      if (!parsed) failMember(member.name, why);
      if (is_positions) {
        if (positions_.member)
          failMember(member.name, "a second positions array besides " + positions_.member->name);
        if (parsed->name != "positions" || parsed->components != 3 || !trx::isFloat(parsed->dtype))
          failMember(member.name, "expected positions.3.float16, positions.3.float32 or positions.3.float64");
        positions_.member = &member;
        positions_.name = *parsed;
      } else {
        if (offsets_member) failMember(member.name, "a second offsets array besides " + offsets_member->name);
        if (parsed->name != "offsets" || parsed->components != 1 || !trx::isInteger(parsed->dtype))
          failMember(member.name, "expected offsets.uint32 or offsets.uint64 (or a signed integer type)");
        offsets_member = &member;
        offsets_dtype = parsed->dtype;
      }
    } else if ((folder == "dps" || folder == "dpv") && parts.size() == 2) {
      if (file_name.ends_with(".json")) {
        warn("ignored member " + member.name + " (JSON metadata, not an array)");
        continue;
      }
      if (!parsed) failMember(member.name, why);
      std::vector<ArrayStream>& list = folder == "dps" ? per_streamline_ : per_point_;
      for (const ArrayStream& other : list)
        if (other.name.name == parsed->name)
          failMember(member.name, "a second " + folder + " array named '" + parsed->name + "' besides " +
                                      other.member->name);
      list.push_back({&member, *parsed, nullptr});
    } else if (folder == "groups" && parts.size() == 2) {
      if (!parsed) failMember(member.name, why);
      if (parsed->components != 1 || !trx::isInteger(parsed->dtype))
        failMember(member.name, "group indices must be one integer per entry (expected NAME.uint32)");
      for (const trx::MemberName& other : group_names)
        if (other.name == parsed->name) failMember(member.name, "a second group named '" + parsed->name + "'");
      group_members.push_back(&member);
      group_names.push_back(*parsed);
    } else if (folder == "dpg" && parts.size() == 3) {
      dpg_members.push_back(&member);
    } else {
      warn("ignored member " + member.name + " (not part of the TRX layout)");
    }
  }

  if (!positions_.member) fail(header_.path, "missing member positions.3.DTYPE (the vertices)");
  if (!offsets_member) fail(header_.path, "missing member offsets.DTYPE (where each streamline starts)");
  checkSize(*positions_.member, nb_vertices_, "NB_VERTICES", 3, positions_.name.dtype);
  readOffsets(*offsets_member, offsets_dtype);
  for (const ArrayStream& s : per_streamline_)
    checkSize(*s.member, nb_streamlines_, "NB_STREAMLINES", s.name.components, s.name.dtype);
  for (const ArrayStream& s : per_point_)
    checkSize(*s.member, nb_vertices_, "NB_VERTICES", s.name.components, s.name.dtype);
  for (size_t i = 0; i < group_members.size(); ++i) readGroup(*group_members[i], group_names[i]);
  for (const trx::Member* member : dpg_members) {
    const std::vector<std::string_view> parts = splitPath(member->name);
    readDataPerGroup(*member, std::string(parts[1]), std::string(parts[2]));
  }

  positions_.reader = archive_.open(*positions_.member);
  for (ArrayStream& stream : per_streamline_) {
    stream.reader = archive_.open(*stream.member);
    header_.per_streamline.push_back({stream.name.name, stream.name.components, trx::dtypeName(stream.name.dtype), {}});
  }
  for (ArrayStream& stream : per_point_) {
    stream.reader = archive_.open(*stream.member);
    header_.per_point.push_back({stream.name.name, stream.name.components, trx::dtypeName(stream.name.dtype), {}});
  }
}

void TrxReader::readOffsets(const trx::Member& member, trx::DType dtype) {
  const uint64_t size = trx::dtypeSize(dtype);
  // Current spec: NB_STREAMLINES + 1 values ending in NB_VERTICES; older files: NB_STREAMLINES values.
  const uint64_t stored = member.size / size;
  if (member.size % size != 0 || (stored != nb_streamlines_ && stored != nb_streamlines_ + 1))
    failMember(member.name, "holds " + std::to_string(member.size) + " bytes, expected " +
                                std::to_string((nb_streamlines_ + 1) * size) + " (NB_STREAMLINES + 1 = " +
                                std::to_string(nb_streamlines_ + 1) + " offsets x " + std::to_string(size) +
                                " bytes; files without the final offset: " + std::to_string(nb_streamlines_ * size) +
                                ")");
  auto reader = archive_.open(member);
  offsets_.clear();
  uint64_t done = 0;
  while (done < stored) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(kDecodeStep, stored - done));
    const uint8_t* p = reader->next(n * size);
    const size_t old = offsets_.size();
    offsets_.resize(old + n);
    const size_t negative = trx::decodeIndices(dtype, p, n, offsets_.data() + old);
    if (negative != n) failMember(member.name, "offset " + std::to_string(done + negative) + " is negative");
    done += n;
  }
  reader->finish();
  fixed_bytes_read_ += member.stored_size;

  if (stored == nb_streamlines_) {
    offsets_.push_back(nb_vertices_);
  } else if (offsets_.back() != nb_vertices_) {
    failMember(member.name, "final offset is " + std::to_string(offsets_.back()) + ", expected NB_VERTICES " +
                                std::to_string(nb_vertices_));
  }
  if (nb_streamlines_ == 0 && nb_vertices_ != 0)
    fail(header_.path, "header.json declares NB_STREAMLINES 0 but NB_VERTICES " + std::to_string(nb_vertices_));
  if (offsets_[0] != 0)
    failMember(member.name, "first offset is " + std::to_string(offsets_[0]) + ", expected 0");
  for (uint64_t i = 1; i <= nb_streamlines_; ++i) {
    if (offsets_[i] >= offsets_[i - 1]) continue;
    if (i == nb_streamlines_)
      failMember(member.name, "streamline " + std::to_string(i - 1) + " starts at vertex " +
                                  std::to_string(offsets_[i - 1]) + ", past NB_VERTICES " +
                                  std::to_string(nb_vertices_));
    failMember(member.name, "offsets decrease: streamline " + std::to_string(i) + " starts at vertex " +
                                std::to_string(offsets_[i]) + ", before streamline " + std::to_string(i - 1) +
                                " at " + std::to_string(offsets_[i - 1]));
  }
}

void TrxReader::readGroup(const trx::Member& member, const trx::MemberName& name) {
  const uint64_t size = trx::dtypeSize(name.dtype);
  if (member.size % size != 0)
    failMember(member.name, "holds " + std::to_string(member.size) + " bytes, not a whole number of " +
                                trx::dtypeName(name.dtype) + " indices");
  const uint64_t count = member.size / size;
  Group group;
  group.name = name.name;
  auto reader = archive_.open(member);
  std::vector<uint64_t> indices;
  uint64_t done = 0;
  while (done < count) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(kDecodeStep, count - done));
    indices.resize(n);
    const size_t negative = trx::decodeIndices(name.dtype, reader->next(n * size), n, indices.data());
    if (negative != n) failMember(member.name, "index " + std::to_string(done + negative) + " is negative");
    for (size_t i = 0; i < n; ++i) {
      if (indices[i] >= nb_streamlines_)
        failMember(member.name, "entry " + std::to_string(done + i) + " is streamline " + std::to_string(indices[i]) +
                                    ", out of range (NB_STREAMLINES " + std::to_string(nb_streamlines_) + ")");
      if (indices[i] > std::numeric_limits<uint32_t>::max())
        failMember(member.name, "streamline indices above 2^32 are not supported");
      group.streamlines.push_back(static_cast<uint32_t>(indices[i]));
    }
    done += n;
  }
  reader->finish();
  fixed_bytes_read_ += member.stored_size;
  header_.groups.push_back(std::move(group));
}

// Data per group is small; it is kept as a property "dpg/GROUP/FILE" whose
// value is the JSON list of values, so a TRX writer can store it back.
void TrxReader::readDataPerGroup(const trx::Member& member, const std::string& group, const std::string& file_name) {
  const bool known_group = std::any_of(header_.groups.begin(), header_.groups.end(),
                                       [&](const Group& g) { return g.name == group; });
  if (!known_group) {
    warn("ignored member " + member.name + " (data for group '" + group + "', which has no groups/ member)");
    return;
  }
  std::string why;
  const auto parsed = trx::parseMemberName(file_name, &why);
  if (!parsed) failMember(member.name, why);
  const uint64_t value_bytes = trx::dtypeSize(parsed->dtype) * parsed->components;
  if (member.size % value_bytes != 0)
    failMember(member.name, "holds " + std::to_string(member.size) + " bytes, not a whole number of " +
                                std::to_string(parsed->components) + "-component " + trx::dtypeName(parsed->dtype) +
                                " values");
  if (member.size > kMaxDpgBytes) {
    warn("ignored member " + member.name + " (" + std::to_string(member.size) + " bytes of data per group)");
    return;
  }
  const std::string bytes = archive_.readWhole(member, kMaxDpgBytes);
  std::vector<float> values(bytes.size() / trx::dtypeSize(parsed->dtype));
  trx::decodeToFloat(parsed->dtype, reinterpret_cast<const uint8_t*>(bytes.data()), values.size(), values.data());
  header_.properties.emplace_back(member.name, nlohmann::json(values).dump());
}

void TrxReader::appendValues(ArrayStream& stream, uint64_t count, std::vector<float>& out) {
  const size_t size = trx::dtypeSize(stream.name.dtype);
  uint64_t done = 0;
  while (done < count) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(kDecodeStep, count - done));
    const uint8_t* p = stream.reader->next(n * size);
    const size_t old = out.size();
    out.resize(old + n);
    trx::decodeToFloat(stream.name.dtype, p, n, out.data() + old);
    done += n;
  }
}

bool TrxReader::read(Tractogram& chunk, size_t max_points) {
  startChunk(chunk);
  if (next_streamline_ >= nb_streamlines_) return false;

  // Whole streamlines up to max_points points (and at most max_points
  // streamlines, which matters only for runs of empty ones); at least one.
  const uint64_t first = next_streamline_;
  const uint64_t budget = std::clamp<uint64_t>(max_points, 1, kMaxCount);
  const auto limit = offsets_.begin() + static_cast<ptrdiff_t>(std::min(nb_streamlines_, first + budget)) + 1;
  const auto end = std::upper_bound(offsets_.begin() + static_cast<ptrdiff_t>(first) + 1, limit,
                                    offsets_[first] + budget);
  const uint64_t last = std::max<uint64_t>(first + 1, static_cast<uint64_t>(end - offsets_.begin()) - 1);
  const uint64_t points = offsets_[last] - offsets_[first];

  chunk.offsets.reserve(static_cast<size_t>(last - first + 1));
  for (uint64_t i = first + 1; i <= last; ++i) chunk.offsets.push_back(offsets_[i] - offsets_[first]);
  appendValues(positions_, 3 * points, chunk.positions);
  for (size_t i = 0; i < chunk.positions.size(); ++i)
    if (!std::isfinite(chunk.positions[i]))
      failMember(positions_.member->name, "vertex " + std::to_string(offsets_[first] + i / 3) +
                                              " has a non-finite coordinate (" + std::to_string(chunk.positions[i]) +
                                              ")");
  for (size_t a = 0; a < per_point_.size(); ++a)
    appendValues(per_point_[a], points * per_point_[a].name.components, chunk.per_point[a].values);
  for (size_t a = 0; a < per_streamline_.size(); ++a)
    appendValues(per_streamline_[a], (last - first) * per_streamline_[a].name.components,
                 chunk.per_streamline[a].values);
  next_streamline_ = last;

  if (next_streamline_ == nb_streamlines_) {
    positions_.reader->finish();
    for (ArrayStream& s : per_point_) s.reader->finish();
    for (ArrayStream& s : per_streamline_) s.reader->finish();
  }
  return true;
}

uint64_t TrxReader::bytesRead() const {
  uint64_t bytes = fixed_bytes_read_ + positions_.reader->fileBytesConsumed();
  for (const ArrayStream& s : per_point_) bytes += s.reader->fileBytesConsumed();
  for (const ArrayStream& s : per_streamline_) bytes += s.reader->fileBytesConsumed();
  return bytes;
}

}  // namespace

std::unique_ptr<TractogramReader> openTrx(const std::string& path) { return std::make_unique<TrxReader>(path); }

}  // namespace fibscope
