// Legacy VTK PolyData reader (".vtk", "# vtk DataFile Version x.y").
//
// Layout (VTK file formats, legacy section): a version line, a title line,
// ASCII or BINARY, "DATASET POLYDATA", then keyword sections: POINTS n type;
// VERTICES / LINES / POLYGONS / TRIANGLE_STRIPS as cell arrays; POINT_DATA n
// and CELL_DATA n followed by attributes (SCALARS, VECTORS, FIELD, ...).
// Binary data is big-endian and starts after the newline that ends its
// keyword line. Cell arrays come in two layouts:
//   classic (before 5.1):  LINES n size, then n records "k id0 .. id(k-1)"
//                          (size = n + sum k values; int32 in binary files)
//   5.1:                   LINES n_offsets n_connectivity, then
//                          OFFSETS type (n_offsets values, first 0, last
//                          n_connectivity) and CONNECTIVITY type.
// Each line cell is a streamline whose points are gathered by index, so the
// POINTS array (and point data) is held in memory; streamlines are handed
// out in chunks. Points are taken as RAS+ mm, except in files whose title
// says "SPACE=LPS" (3D Slicer and SlicerDMRI write legacy files with a
// "SPACE=RAS" or "SPACE=LPS" title), where x and y are negated. Binary cell
// arrays are read from the map when gathered; ASCII ones are parsed once at
// open.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>
#include <string_view>
#include <unordered_set>

#include "core/byte_order.h"
#include "core/error.h"
#include "core/mapped_file.h"
#include "io/indexed_lines.h"
#include "io/reader.h"

namespace fibscope {
namespace {

enum class Scalar { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kInt64, kUInt64, kFloat32, kFloat64, kBit, kString };

struct ValueType {
  Scalar scalar = Scalar::kFloat32;
  size_t bytes = 4;
  // Bit and string arrays (no fixed byte size) are neither integral nor floating.
  bool integral() const {
    return scalar != Scalar::kFloat32 && scalar != Scalar::kFloat64 && scalar != Scalar::kBit &&
           scalar != Scalar::kString;
  }
};

std::string lowerCase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// Type names of the legacy format. "vtkIdType" is written as 32-bit int and
// "long" with the writer's sizeof(long), 8 bytes on the LP64 systems that
// write these files.
std::optional<ValueType> valueTypeOf(std::string_view name) {
  const std::string n = lowerCase(name);
  if (n == "char" || n == "signed_char" || n == "vtktypeint8") return ValueType{Scalar::kInt8, 1};
  if (n == "unsigned_char" || n == "vtktypeuint8") return ValueType{Scalar::kUInt8, 1};
  if (n == "short" || n == "vtktypeint16") return ValueType{Scalar::kInt16, 2};
  if (n == "unsigned_short" || n == "vtktypeuint16") return ValueType{Scalar::kUInt16, 2};
  if (n == "int" || n == "vtktypeint32" || n == "vtkidtype") return ValueType{Scalar::kInt32, 4};
  if (n == "unsigned_int" || n == "vtktypeuint32") return ValueType{Scalar::kUInt32, 4};
  if (n == "long" || n == "vtktypeint64") return ValueType{Scalar::kInt64, 8};
  if (n == "unsigned_long" || n == "vtktypeuint64") return ValueType{Scalar::kUInt64, 8};
  if (n == "float" || n == "vtktypefloat32") return ValueType{Scalar::kFloat32, 4};
  if (n == "double" || n == "vtktypefloat64") return ValueType{Scalar::kFloat64, 8};
  if (n == "bit") return ValueType{Scalar::kBit, 0};
  if (n == "string" || n == "utf8_string") return ValueType{Scalar::kString, 0};
  return std::nullopt;
}

std::string upperCase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

bool isSpace(uint8_t c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

// Text from the file for messages: printable ASCII, at most 40 characters.
std::string shown(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (s.size() > 40) out += "...";
  return out;
}

// Text that is not valid UTF-8 is read as latin-1, so that every later
// writer (JSON in TRX) can store it.
std::string validUtf8(const std::string& s) {
  bool valid = true;
  for (size_t i = 0; i < s.size() && valid;) {
    const unsigned char c = s[i];
    const size_t n = c < 0x80 ? 1 : (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
    valid = n > 0 && i + n <= s.size() && c != 0;
    for (size_t k = 1; valid && k < n; ++k) valid = (static_cast<unsigned char>(s[i + k]) & 0xC0) == 0x80;
    i += n;
  }
  if (valid) return s;
  std::string latin;
  for (unsigned char c : s) {
    if (c == 0) continue;
    if (c < 0x80) {
      latin += static_cast<char>(c);
    } else {
      latin += static_cast<char>(0xC0 | (c >> 6));
      latin += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return latin;
}

// Array names: VTK escapes unusual characters as %XX.
std::string decodeName(std::string_view raw) {
  std::string s;
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] == '%' && i + 2 < raw.size() && std::isxdigit(static_cast<unsigned char>(raw[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(raw[i + 2]))) {
      s += static_cast<char>(std::stoi(std::string(raw.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      s += raw[i];
    }
  }
  return validUtf8(s);
}

// Reads tokens, counts and arrays from the mapped file; every read is checked
// against the end of the file and throws a one-line Error naming the offset.
class VtkCursor {
 public:
  VtkCursor(const uint8_t* data, size_t size, const std::string& path, bool binary = false)
      : data_(data), size_(size), path_(path), binary_(binary) {}
  void setBinary(bool binary) { binary_ = binary; }
  bool binary() const { return binary_; }
  uint64_t offset() const { return pos_; }
  const uint8_t* at() const { return data_ + pos_; }
  uint64_t remaining() const { return size_ - pos_; }
  [[noreturn]] void fail(const std::string& message) const { failAt(path_, pos_, message); }
  [[noreturn]] void failAtOffset(uint64_t offset, const std::string& message) const {
    failAt(path_, offset, message);
  }

  void skipSpace() {
    while (pos_ < size_ && isSpace(data_[pos_])) ++pos_;
  }
  // Next whitespace-delimited token ("" at the end of the file).
  std::string_view token() {
    skipSpace();
    const size_t begin = pos_;
    while (pos_ < size_ && !isSpace(data_[pos_])) ++pos_;
    return {reinterpret_cast<const char*>(data_ + begin), pos_ - begin};
  }
  // Next token if it is on the current line, else "" (nothing consumed).
  std::string_view tokenOnLine() {
    size_t p = pos_;
    while (p < size_ && (data_[p] == ' ' || data_[p] == '\t' || data_[p] == '\r')) ++p;
    if (p >= size_ || data_[p] == '\n') return {};
    pos_ = p;
    return token();
  }
  // The rest of the current line without its '\r\n' / '\n'; moves past it.
  std::string_view restOfLine() {
    const size_t begin = pos_;
    while (pos_ < size_ && data_[pos_] != '\n') ++pos_;
    size_t end = pos_;
    if (pos_ < size_) ++pos_;
    if (end > begin && data_[end - 1] == '\r') --end;
    return {reinterpret_cast<const char*>(data_ + begin), end - begin};
  }
  // Binary data starts after the newline that ends its keyword line.
  void startData() {
    if (binary_) restOfLine();
  }
  // True if the next word is `lower_word`, case-insensitively (nothing is
  // consumed but whitespace). At the start of binary data whitespace is not
  // skipped: those bytes may be data.
  bool nextWordIs(std::string_view lower_word, bool at_data_start = false) {
    if (!binary_ || !at_data_start) skipSpace();
    if (remaining() < lower_word.size()) return false;
    for (size_t i = 0; i < lower_word.size(); ++i)
      if (std::tolower(data_[pos_ + i]) != lower_word[i]) return false;
    return remaining() == lower_word.size() || isSpace(data_[pos_ + lower_word.size()]);
  }
  void expectWord(std::string_view lower_word, const char* context) {
    const uint64_t where = (skipSpace(), pos_);
    const std::string_view t = token();
    if (lowerCase(t) != lower_word)
      failAtOffset(where, std::string("expected ") + lowerCase(lower_word) + " " + context + ", found '" + shown(t) +
                              "'");
  }
  uint64_t count(const char* what) {
    skipSpace();
    const uint64_t where = pos_;
    const std::string_view t = token();
    uint64_t v = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc() || end != t.data() + t.size())
      failAtOffset(where, std::string("expected a non-negative count for ") + what + ", found '" + shown(t) + "'");
    return v;
  }
  ValueType type(const char* what) {
    skipSpace();
    const uint64_t where = pos_;
    const std::string_view t = token();
    const auto type = valueTypeOf(t);
    if (!type) failAtOffset(where, std::string("unknown data type '") + shown(t) + "' for " + what);
    return *type;
  }

  // Reads n values of `type` into out[0..n) (converted to T). For T integral
  // the values must be integers. `what` names the array in messages.
  template <typename T>
  void readValues(const ValueType& type, uint64_t n, T* out, const std::string& what) {
    if (type.scalar == Scalar::kBit || type.scalar == Scalar::kString)
      fail(what + ": bit and string arrays cannot be read as numbers");
    if (binary_) {
      if (n > remaining() / type.bytes)
        fail(what + ": " + std::to_string(n) + " values of " + std::to_string(type.bytes) + " bytes need " +
             std::to_string(n * type.bytes) + " bytes, but only " + std::to_string(remaining()) + " remain");
      const uint8_t* p = data_ + pos_;
      constexpr bool swap = kHostIsLittleEndian;  // legacy binary is big-endian
      for (uint64_t i = 0; i < n; ++i, p += type.bytes) {
        switch (type.scalar) {
          case Scalar::kInt8: out[i] = static_cast<T>(static_cast<int8_t>(*p)); break;
          case Scalar::kUInt8: out[i] = static_cast<T>(*p); break;
          case Scalar::kInt16: out[i] = static_cast<T>(loadUnaligned<int16_t>(p, swap)); break;
          case Scalar::kUInt16: out[i] = static_cast<T>(loadUnaligned<uint16_t>(p, swap)); break;
          case Scalar::kInt32: out[i] = static_cast<T>(loadUnaligned<int32_t>(p, swap)); break;
          case Scalar::kUInt32: out[i] = static_cast<T>(loadUnaligned<uint32_t>(p, swap)); break;
          case Scalar::kInt64: out[i] = static_cast<T>(loadUnaligned<int64_t>(p, swap)); break;
          case Scalar::kUInt64: out[i] = static_cast<T>(loadUnaligned<uint64_t>(p, swap)); break;
          case Scalar::kFloat32: out[i] = convert<T>(loadUnaligned<float>(p, swap), i, what); break;
          case Scalar::kFloat64: out[i] = convert<T>(loadUnaligned<double>(p, swap), i, what); break;
          default: break;
        }
      }
      pos_ += n * type.bytes;
      return;
    }
    // Every ASCII value takes at least one byte: a bound before any allocation.
    if (n > remaining())
      fail(what + ": expects " + std::to_string(n) + " values, but only " + std::to_string(remaining()) +
           " bytes remain");
    for (uint64_t i = 0; i < n; ++i) {
      skipSpace();
      const uint64_t where = pos_;
      const std::string_view t = token();
      if (t.empty())
        failAtOffset(where, what + ": file ends after " + std::to_string(i) + " of " + std::to_string(n) + " values");
      bool ok;
      if constexpr (std::is_integral_v<T>) {
        int64_t v = 0;
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        ok = ec == std::errc() && end == t.data() + t.size();
        out[i] = static_cast<T>(v);
      } else {
        double v = 0;
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        ok = ec == std::errc() && end == t.data() + t.size();
        out[i] = static_cast<T>(v);
      }
      if (!ok)
        failAtOffset(where, what + ": value " + std::to_string(i) + " is '" + shown(t) + "', expected " +
                                (std::is_integral_v<T> ? "an integer" : "a number"));
    }
  }

  // Skips n values of any type, strings and bits included.
  void skipValues(const ValueType& type, uint64_t n, const std::string& what) {
    if (type.scalar == Scalar::kString) {
      if (!binary_) {
        // One string per line after the header line (VTK escapes blanks as %20).
        restOfLine();
        for (uint64_t i = 0; i < n; ++i) {
          if (pos_ >= size_) fail(what + ": file ends inside the strings");
          restOfLine();
        }
        return;
      }
      // Binary strings: a big-endian length whose top two bits give its size
      // (11: 1 byte, 10: 2 bytes, 01: 4 bytes, 00: 8 bytes), then the bytes.
      for (uint64_t i = 0; i < n; ++i) {
        if (remaining() < 1) fail(what + ": file ends inside the strings");
        const unsigned tag = data_[pos_] >> 6;
        const size_t header = tag == 3 ? 1 : tag == 2 ? 2 : tag == 1 ? 4 : 8;
        if (remaining() < header) fail(what + ": file ends inside a string length");
        uint64_t length = 0;
        for (size_t k = 0; k < header; ++k) length = (length << 8) | data_[pos_ + k];
        if (header < 8) length &= (uint64_t(1) << (8 * header - 2)) - 1;
        if (length > remaining() - header) fail(what + ": string " + std::to_string(i) + " runs past the end of the file");
        pos_ += header + length;
      }
      return;
    }
    if (type.scalar == Scalar::kBit && binary_) {
      const uint64_t bytes = n / 8 + (n % 8 != 0);
      if (bytes > remaining()) fail(what + ": bit array runs past the end of the file");
      pos_ += bytes;
      return;
    }
    if (!binary_) {
      if (n > remaining()) fail(what + ": expects " + std::to_string(n) + " values, but only " +
                                std::to_string(remaining()) + " bytes remain");
      for (uint64_t i = 0; i < n; ++i)
        if (token().empty()) fail(what + ": file ends after " + std::to_string(i) + " of " + std::to_string(n) + " values");
      return;
    }
    if (n > remaining() / type.bytes)
      fail(what + ": " + std::to_string(n) + " values need more bytes than the " + std::to_string(remaining()) +
           " that remain");
    pos_ += n * type.bytes;
  }

  // Skips `bytes` of binary data (checked).
  void skipBytes(uint64_t bytes, const std::string& what) {
    if (bytes > remaining()) fail(what + ": runs past the end of the file");
    pos_ += bytes;
  }

 private:
  template <typename T, typename F>
  T convert(F v, uint64_t i, const std::string& what) const {
    if constexpr (std::is_integral_v<T>) {
      if (!(v == std::floor(v)) || std::fabs(double(v)) > 9e18)
        fail(what + ": value " + std::to_string(i) + " is not an integer");
    }
    return static_cast<T>(v);
  }

  const uint8_t* data_;
  size_t size_;
  std::string path_;
  bool binary_;
  uint64_t pos_ = 0;
};

// One cell array (VERTICES, LINES, ...): cell i holds connectivity entries
// [offsets[i], offsets[i+1]).
struct CellArray {
  std::vector<uint64_t> offsets = {0};
  std::vector<int64_t> ids;           // ASCII files: the entries, parsed
  const uint8_t* raw = nullptr;       // binary files: the entries in the map (big-endian)
  ValueType raw_type;
  bool interleaved = false;           // classic binary layout: a count word precedes each cell
  uint64_t data_offset = 0;           // file offset of the entries, for messages

  uint64_t cellCount() const { return offsets.size() - 1; }
  uint64_t word(uint64_t cell, uint64_t j) const { return offsets[cell] + j + (interleaved ? cell + 1 : 0); }
  int64_t id(uint64_t cell, uint64_t j) const {
    const uint64_t w = word(cell, j);
    if (!raw) return ids[w];
    constexpr bool swap = kHostIsLittleEndian;
    const uint8_t* p = raw + w * raw_type.bytes;
    switch (raw_type.scalar) {
      case Scalar::kInt8: return static_cast<int8_t>(*p);
      case Scalar::kUInt8: return *p;
      case Scalar::kInt16: return loadUnaligned<int16_t>(p, swap);
      case Scalar::kUInt16: return loadUnaligned<uint16_t>(p, swap);
      case Scalar::kInt32: return loadUnaligned<int32_t>(p, swap);
      case Scalar::kUInt32: return loadUnaligned<uint32_t>(p, swap);
      case Scalar::kUInt64: {
        const uint64_t v = loadUnaligned<uint64_t>(p, swap);
        return v > uint64_t(INT64_MAX) ? -1 : int64_t(v);
      }
      default: return loadUnaligned<int64_t>(p, swap);
    }
  }
  // Where entry j of `cell` is in the file (exact for binary, the start of the
  // section for ASCII).
  uint64_t entryOffset(uint64_t cell, uint64_t j) const {
    return raw ? data_offset + word(cell, j) * raw_type.bytes : data_offset;
  }
};

enum class Owner { kNone, kPoints, kCells };

class VtkReader final : public TractogramReader {
 public:
  explicit VtkReader(const std::string& path);
  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override {
    const uint64_t lines = lines_.cellCount();
    return lines == 0 || next_line_ >= lines ? file_.size() : header_end_ + (file_.size() - header_end_) * next_line_ / lines;
  }

 private:
  void parse(VtkCursor& c);
  void parsePoints(VtkCursor& c);
  CellArray parseCells(VtkCursor& c, const std::string& keyword);
  void parseAttribute(VtkCursor& c, const std::string& keyword, Owner owner, uint64_t count);
  void parseField(VtkCursor& c, Owner owner, uint64_t count);
  void readArray(VtkCursor& c, std::string name, const ValueType& type, uint64_t tuples, uint32_t components,
                 Owner owner, const std::string& what, bool color = false);
  void skipMetadata(VtkCursor& c);

  MappedFile file_;
  std::vector<float> points_;
  uint64_t point_count_ = 0;
  bool have_points_ = false;
  bool have_lines_ = false;
  CellArray lines_;
  uint64_t other_cells_ = 0;          // vertices, polygons, strips: not streamlines
  uint64_t vertex_cells_ = 0;         // of those, vertices (numbered before the lines)
  std::vector<DataArray> point_arrays_;  // values per point id
  std::vector<DataArray> line_arrays_;   // values per line cell
  uint64_t header_end_ = 0;
  uint64_t next_line_ = 0;
  bool lps_ = false;  // points are stored in LPS: negate x and y
};

VtkReader::VtkReader(const std::string& path) : file_(path) {
  header_.path = path;
  header_.format = "vtk";
  header_.file_bytes = file_.size();
  VtkCursor c(file_.data(), file_.size(), path);

  const std::string_view first = c.restOfLine();
  constexpr std::string_view kMagic = "# vtk datafile version";
  if (first.size() < kMagic.size() || lowerCase(first.substr(0, kMagic.size())) != kMagic)
    failAt(path, 0, "expected '# vtk DataFile Version x.y', found '" + shown(first) + "'");
  std::string version(first.substr(kMagic.size()));
  version.erase(0, version.find_first_not_of(' '));
  const std::string title = validUtf8(std::string(c.restOfLine()));
  const uint64_t encoding_at = c.offset();
  const std::string encoding = lowerCase(c.token());
  if (encoding != "ascii" && encoding != "binary")
    failAt(path, encoding_at, "expected ASCII or BINARY, found '" + shown(encoding) + "'");
  c.setBinary(encoding == "binary");
  c.skipSpace();
  const uint64_t dataset_at = c.offset();
  const std::string dataset = lowerCase(c.token());
  const std::string kind = lowerCase(c.token());
  if (dataset != "dataset" || kind != "polydata")
    failAt(path, dataset_at, "expected DATASET POLYDATA, found '" + shown(dataset + " " + kind) + "'");
  c.restOfLine();

  header_.properties = {{"vtk.version", version}, {"vtk.title", title}, {"vtk.encoding", encoding}};
  const std::string upper_title = upperCase(title);
  const size_t space_at = upper_title.find("SPACE=");
  if (space_at != std::string::npos) {
    const std::string space = upper_title.substr(space_at + 6, 3);
    if (space == "LPS" || space == "RAS") header_.properties.emplace_back("vtk.space", space);
    lps_ = space == "LPS";
  }
  parse(c);
  header_end_ = c.offset();

  if (lines_.offsets.back() > 0 && !have_points_) fail(path, "LINES refer to points, but the file has no POINTS");
  if (!have_lines_) warn("no LINES section: the file holds no streamlines");
  header_.declared_streamlines = int64_t(lines_.cellCount());
  header_.declared_points = int64_t(lines_.offsets.back());
  for (const auto& a : point_arrays_) header_.per_point.push_back({a.name, a.components, a.dtype, {}});
  for (const auto& a : line_arrays_) header_.per_streamline.push_back({a.name, a.components, a.dtype, {}});
}

void VtkReader::parse(VtkCursor& c) {
  Owner owner = Owner::kNone;
  uint64_t owner_count = 0;
  for (;;) {
    c.skipSpace();
    const uint64_t keyword_at = c.offset();
    const std::string_view raw_keyword = c.token();
    const std::string keyword = lowerCase(raw_keyword);
    if (keyword.empty()) break;
    if (keyword == "points") {
      if (have_points_) c.failAtOffset(keyword_at, "second POINTS section");
      parsePoints(c);
    } else if (keyword == "lines" || keyword == "vertices" || keyword == "polygons" || keyword == "triangle_strips") {
      if (owner != Owner::kNone) c.failAtOffset(keyword_at, "cells after POINT_DATA or CELL_DATA");
      CellArray cells = parseCells(c, keyword);
      if (keyword == "lines") {
        if (have_lines_) c.failAtOffset(keyword_at, "second LINES section");
        have_lines_ = true;
        lines_ = std::move(cells);
      } else {
        other_cells_ += cells.cellCount();
        if (keyword == "vertices") vertex_cells_ += cells.cellCount();
        if (cells.cellCount() > 0)
          warn(std::to_string(cells.cellCount()) + " " + keyword + " cells are not streamlines; skipped");
      }
    } else if (keyword == "point_data" || keyword == "cell_data") {
      owner_count = c.count(keyword == "point_data" ? "POINT_DATA" : "CELL_DATA");
      if (keyword == "point_data") {
        if (owner_count != point_count_)
          c.failAtOffset(keyword_at, "POINT_DATA has " + std::to_string(owner_count) + " values, POINTS has " +
                                         std::to_string(point_count_));
        owner = Owner::kPoints;
      } else {
        const uint64_t cells = lines_.cellCount() + other_cells_;
        if (owner_count != cells)
          c.failAtOffset(keyword_at, "CELL_DATA has " + std::to_string(owner_count) + " values, the file has " +
                                         std::to_string(cells) + " cells");
        owner = Owner::kCells;
      }
    } else if (keyword == "field") {
      parseField(c, owner, owner_count);
    } else if (keyword == "metadata") {
      skipMetadata(c);
    } else if (keyword == "scalars" || keyword == "color_scalars" || keyword == "lookup_table" ||
               keyword == "vectors" || keyword == "normals" || keyword == "texture_coordinates" ||
               keyword == "tensors" || keyword == "tensors6" || keyword == "global_ids" ||
               keyword == "pedigree_ids" || keyword == "edge_flags") {
      if (owner == Owner::kNone)
        c.failAtOffset(keyword_at, "attribute " + keyword + " before POINT_DATA or CELL_DATA");
      parseAttribute(c, keyword, owner, owner_count);
    } else {
      c.failAtOffset(keyword_at, "unexpected keyword '" + shown(raw_keyword) +
                                     "' (expected POINTS, LINES, POLYGONS, VERTICES, POINT_DATA, CELL_DATA or an "
                                     "attribute)");
    }
  }
}

void VtkReader::parsePoints(VtkCursor& c) {
  point_count_ = c.count("POINTS");
  const ValueType type = c.type("POINTS");
  if (type.scalar == Scalar::kBit || type.scalar == Scalar::kString) c.fail("POINTS must be numeric");
  if (point_count_ > (uint64_t(1) << 40)) c.fail("POINTS count " + std::to_string(point_count_) + " is absurd");
  c.startData();
  const uint64_t values = 3 * point_count_;
  // The bound is checked (by readValues) before this allocation is sized.
  if (values > (c.binary() ? c.remaining() / type.bytes : c.remaining()))
    c.fail("POINTS: " + std::to_string(point_count_) + " points need more bytes than the " +
           std::to_string(c.remaining()) + " that remain");
  points_.resize(values);
  c.readValues(type, values, points_.data(), "POINTS");
  have_points_ = true;
}

CellArray VtkReader::parseCells(VtkCursor& c, const std::string& keyword) {
  const std::string label = upperCase(keyword);
  const uint64_t first = c.count(label.c_str());
  const uint64_t second = c.count(label.c_str());
  c.startData();
  CellArray cells;
  if (c.nextWordIs("offsets", true)) {
    // VTK 5.1: first = number of offsets (cells + 1), second = connectivity size.
    c.token();
    const ValueType offset_type = c.type((label + " OFFSETS").c_str());
    if (!offset_type.integral()) c.fail(label + " OFFSETS must have an integer type");
    c.startData();
    if (first > (c.binary() ? c.remaining() / offset_type.bytes : c.remaining()))
      c.fail(label + " OFFSETS: " + std::to_string(first) + " offsets need more bytes than remain");
    const uint64_t offsets_at = c.offset();
    std::vector<int64_t> offsets(first);
    c.readValues(offset_type, first, offsets.data(), label + " OFFSETS");
    if (first > 0 && offsets[0] != 0) c.failAtOffset(offsets_at, label + " OFFSETS must start at 0");
    for (uint64_t i = 1; i < first; ++i)
      if (offsets[i] < offsets[i - 1])
        c.failAtOffset(offsets_at, label + " OFFSETS decrease at cell " + std::to_string(i - 1));
    if (first > 0 && uint64_t(offsets.back()) != second)
      c.failAtOffset(offsets_at, label + " OFFSETS end at " + std::to_string(offsets.back()) +
                                     ", the connectivity has " + std::to_string(second) + " entries");
    if (first == 0 && second != 0) c.failAtOffset(offsets_at, label + " has no OFFSETS but connectivity entries");
    cells.offsets.assign(offsets.begin(), offsets.end());
    if (cells.offsets.empty()) cells.offsets = {0};

    c.expectWord("connectivity", ("after " + label + " OFFSETS").c_str());
    const ValueType id_type = c.type((label + " CONNECTIVITY").c_str());
    if (!id_type.integral()) c.fail(label + " CONNECTIVITY must have an integer type");
    c.startData();
    cells.data_offset = c.offset();
    if (c.binary()) {
      cells.raw = c.at();
      cells.raw_type = id_type;
      c.skipBytes(second > c.remaining() / id_type.bytes ? c.remaining() + 1 : second * id_type.bytes,
                  label + " CONNECTIVITY");
    } else {
      if (second > c.remaining()) c.fail(label + " CONNECTIVITY: more entries than bytes remain");
      cells.ids.resize(second);
      c.readValues(id_type, second, cells.ids.data(), label + " CONNECTIVITY");
    }
    return cells;
  }

  // Classic layout: first = cells, second = total words (counts + ids).
  const uint64_t n = first, size = second;
  cells.data_offset = c.offset();
  if (size > (c.binary() ? c.remaining() / 4 : c.remaining()))
    c.fail(label + ": " + std::to_string(size) + " entries need more bytes than the " +
           std::to_string(c.remaining()) + " that remain");
  if (n > size) c.fail(label + ": " + std::to_string(n) + " cells cannot fit in " + std::to_string(size) + " entries");
  cells.offsets.reserve(n + 1);
  uint64_t w = 0;
  if (c.binary()) {
    cells.raw = c.at();
    cells.raw_type = ValueType{Scalar::kInt32, 4};
    cells.interleaved = true;
    for (uint64_t i = 0; i < n; ++i) {
      if (w >= size)
        c.failAtOffset(cells.data_offset + 4 * w, label + " declares " + std::to_string(size) +
                                                      " entries, but they end before cell " + std::to_string(i));
      const int32_t k = loadUnaligned<int32_t>(cells.raw + 4 * w, kHostIsLittleEndian);
      if (k < 0 || uint64_t(k) > size - w - 1)
        c.failAtOffset(cells.data_offset + 4 * w, label + " cell " + std::to_string(i) + " has " + std::to_string(k) +
                                                      " points, but only " + std::to_string(size - w - 1) +
                                                      " entries remain in the section");
      cells.offsets.push_back(cells.offsets.back() + uint64_t(k));
      w += 1 + uint64_t(k);
    }
    if (w != size)
      c.failAtOffset(cells.data_offset, label + " declares " + std::to_string(size) + " entries, its " +
                                            std::to_string(n) + " cells use " + std::to_string(w));
    c.skipBytes(4 * size, label);
    return cells;
  }
  cells.ids.reserve(size - n);
  for (uint64_t i = 0; i < n; ++i) {
    if (w >= size)
      c.fail(label + " declares " + std::to_string(size) + " entries, but they end before cell " + std::to_string(i));
    int64_t k = 0;
    c.readValues(ValueType{Scalar::kInt32, 4}, 1, &k, label + " cell " + std::to_string(i) + " size");
    if (k < 0 || uint64_t(k) > size - w - 1)
      c.fail(label + " cell " + std::to_string(i) + " has " + std::to_string(k) + " points, but only " +
             std::to_string(size - w - 1) + " entries remain in the section");
    const size_t base = cells.ids.size();
    cells.ids.resize(base + uint64_t(k));
    c.readValues(ValueType{Scalar::kInt64, 8}, uint64_t(k), cells.ids.data() + base,
                 label + " cell " + std::to_string(i));
    cells.offsets.push_back(cells.offsets.back() + uint64_t(k));
    w += 1 + uint64_t(k);
  }
  if (w != size)
    c.failAtOffset(cells.data_offset, label + " declares " + std::to_string(size) + " entries, its " +
                                          std::to_string(n) + " cells use " + std::to_string(w));
  return cells;
}

void VtkReader::parseAttribute(VtkCursor& c, const std::string& keyword, Owner owner, uint64_t count) {
  const std::string label = upperCase(keyword);
  const std::string name = decodeName(c.token());
  if (keyword == "lookup_table") {
    // A colour table for SCALARS: size RGBA entries, floats in ASCII, bytes in binary.
    const uint64_t size = c.count("LOOKUP_TABLE");
    c.startData();
    if (c.binary()) {
      if (size > c.remaining() / 4) c.fail("LOOKUP_TABLE '" + name + "' runs past the end of the file");
      c.skipBytes(4 * size, "LOOKUP_TABLE");
    } else {
      c.skipValues(ValueType{Scalar::kFloat32, 4}, size > UINT64_MAX / 4 ? UINT64_MAX : 4 * size,
                   "LOOKUP_TABLE '" + name + "'");
    }
    return;
  }
  if (keyword == "color_scalars") {
    const uint64_t components = c.count("COLOR_SCALARS");
    if (components == 0 || components > 4096) c.fail("COLOR_SCALARS '" + name + "' has " + std::to_string(components) + " components");
    c.startData();
    readArray(c, name, c.binary() ? ValueType{Scalar::kUInt8, 1} : ValueType{Scalar::kFloat32, 4}, count,
              uint32_t(components), owner, "COLOR_SCALARS '" + name + "'", true);
    return;
  }
  uint64_t components = 1;
  if (keyword == "texture_coordinates") components = c.count("TEXTURE_COORDINATES dimension");
  const ValueType type = c.type(("attribute '" + name + "'").c_str());
  if (keyword == "scalars") {
    const std::string_view n = c.tokenOnLine();
    if (!n.empty()) {
      const auto [end, ec] = std::from_chars(n.data(), n.data() + n.size(), components);
      if (ec != std::errc() || end != n.data() + n.size())
        c.fail("SCALARS '" + name + "': component count is '" + shown(n) + "'");
    }
    c.startData();
    if (c.nextWordIs("lookup_table", true)) {
      c.token();
      c.token();  // table name ("default")
      c.startData();
    }
  } else {
    if (keyword == "vectors" || keyword == "normals") components = 3;
    if (keyword == "tensors") components = 9;
    if (keyword == "tensors6") components = 6;
    c.startData();
  }
  if (components == 0 || components > 4096)
    c.fail(label + " '" + name + "' has " + std::to_string(components) + " components");
  if (keyword == "global_ids" || keyword == "pedigree_ids" || keyword == "edge_flags") {
    c.skipValues(type, count, label + " '" + name + "'");
    warn(label + " '" + name + "' skipped (ids and flags are not streamline data)");
    return;
  }
  readArray(c, name, type, count, uint32_t(components), owner, label + " '" + name + "'");
}

void VtkReader::parseField(VtkCursor& c, Owner owner, uint64_t count) {
  const std::string field_name = decodeName(c.token());
  const uint64_t arrays = c.count("FIELD array count");
  for (uint64_t i = 0; i < arrays; ++i) {
    while (c.nextWordIs("metadata")) {  // belongs to the previous array
      c.token();
      skipMetadata(c);
    }
    if (c.nextWordIs("null_array")) {
      c.token();
      continue;
    }
    const std::string name = decodeName(c.token());
    if (name.empty()) c.fail("FIELD '" + field_name + "' ends after " + std::to_string(i) + " arrays");
    const uint64_t components = c.count(("FIELD array '" + name + "' components").c_str());
    const uint64_t tuples = c.count(("FIELD array '" + name + "' tuples").c_str());
    const ValueType type = c.type(("FIELD array '" + name + "'").c_str());
    c.startData();
    const std::string what = "FIELD array '" + name + "'";
    if (components > 0 && tuples > UINT64_MAX / components) c.fail(what + ": size overflows");
    const bool numeric = type.scalar != Scalar::kBit && type.scalar != Scalar::kString;
    if (owner == Owner::kNone || tuples != count || !numeric || components == 0 || components > 4096) {
      c.skipValues(type, tuples * components, what);
      warn(what + " skipped (" +
           (owner == Owner::kNone ? std::string("dataset field data")
            : !numeric             ? std::string("not numeric")
                                   : std::to_string(tuples) + " tuples of " + std::to_string(components) +
                                         " components for " + std::to_string(count) + " items") +
           ")");
      continue;
    }
    readArray(c, name, type, tuples, uint32_t(components), owner, what);
  }
  if (c.nextWordIs("metadata")) {
    c.token();
    skipMetadata(c);
  }
}

void VtkReader::readArray(VtkCursor& c, std::string name, const ValueType& type, uint64_t tuples,
                          uint32_t components, Owner owner, const std::string& what, bool color) {
  if (type.scalar == Scalar::kBit || type.scalar == Scalar::kString) {
    c.skipValues(type, tuples * components, what);
    warn(what + " skipped (bit and string arrays are not numeric data)");
    return;
  }
  const uint64_t n = tuples * components;
  if (n > (c.binary() ? c.remaining() / type.bytes : c.remaining()))
    c.fail(what + ": " + std::to_string(n) + " values need more bytes than the " + std::to_string(c.remaining()) +
           " that remain");
  static const char* kTypeNames[] = {"int8",   "uint8",  "int16",   "uint16",  "int32", "uint32",
                                     "int64",  "uint64", "float32", "float64", "bit",   "string"};
  DataArray array{name, components, kTypeNames[int(type.scalar)], std::vector<float>(n)};
  c.readValues(type, n, array.values.data(), what);
  if (color && c.binary())
    for (float& v : array.values) v /= 255.0f;  // binary colour scalars are bytes, ASCII ones 0..1
  if (owner == Owner::kCells && other_cells_ > 0) {
    // vtkPolyData numbers its cells verts, lines, polys, strips, whatever
    // order the sections come in: the lines' rows follow the vertices.
    const uint64_t lines = lines_.cellCount();
    array.values.erase(array.values.begin() + (vertex_cells_ + lines) * components, array.values.end());
    array.values.erase(array.values.begin(), array.values.begin() + vertex_cells_ * components);
  }
  std::vector<DataArray>& arrays = owner == Owner::kPoints ? point_arrays_ : line_arrays_;
  if (array.name.empty()) array.name = "array_" + std::to_string(arrays.size());
  std::unordered_set<std::string> used;
  for (const auto& a : arrays) used.insert(a.name);
  if (used.count(array.name)) {
    std::string renamed = array.name;
    for (int k = 2; used.count(renamed); ++k) renamed = array.name + "_" + std::to_string(k);
    warn(what + " has the name of an earlier array; read as '" + renamed + "'");
    array.name = renamed;
  }
  arrays.push_back(std::move(array));
}

void VtkReader::skipMetadata(VtkCursor& c) {
  // METADATA (VTK >= 8.1): COMPONENT_NAMES and INFORMATION lines, ended by an empty line.
  c.restOfLine();
  while (c.remaining() > 0) {
    const std::string_view line = c.restOfLine();
    if (std::all_of(line.begin(), line.end(), [](char ch) { return isSpace(uint8_t(ch)); })) break;
  }
}

bool VtkReader::read(Tractogram& chunk, size_t max_points) {
  startChunk(chunk);
  const uint64_t lines = lines_.cellCount();
  if (next_line_ >= lines) return false;
  const IndexedPoints src{header_.path, points_, point_arrays_, line_arrays_, lps_};
  while (next_line_ < lines) {
    const uint64_t i = next_line_;
    appendIndexedLine(chunk, src, i, lines_.offsets[i + 1] - lines_.offsets[i], [&](uint64_t j) {
      const int64_t id = lines_.id(i, j);
      if (id < 0 || uint64_t(id) >= point_count_)
        failAt(header_.path, lines_.entryOffset(i, j),
               "line " + std::to_string(i) + " point " + std::to_string(j) + " refers to point " + std::to_string(id) +
                   ", but POINTS has " + std::to_string(point_count_));
      return uint64_t(id);
    });
    ++next_line_;
    if (chunk.pointCount() >= max_points) break;
  }
  return true;
}

}  // namespace

std::unique_ptr<TractogramReader> openVtk(const std::string& path) { return std::make_unique<VtkReader>(path); }

}  // namespace fibscope
