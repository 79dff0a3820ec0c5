// VTK XML PolyData (.vtp): what 3D Slicer (SlicerDMRI), dipy/FURY
// (save_vtk_streamlines) and ParaView write for streamlines.
//
// <VTKFile type="PolyData" byte_order=... header_type=... compressor=...>
//   <PolyData> [<FieldData>] <Piece NumberOfPoints NumberOfLines ...>
//     <Points> one 3-component DataArray
//     <Lines>  DataArrays "connectivity" (point ids) and "offsets" (the end
//              of each line in connectivity: no leading 0)
//     <PointData>, <CellData>  per-point and per-cell arrays
//   </Piece>... </PolyData>
//   [<AppendedData encoding="raw|base64"> _ bytes... </AppendedData>]
// The arrays' bytes: io/vtp_data.h. Cells are ordered verts, lines, polys,
// strips (vtkPolyData), so a line's CellData row is NumberOfVerts + its
// index. Several pieces are concatenated in order.
//
// World space: as stored, except Slicer's LPS files (a FieldData string
// <Array> "SPACE" holding "LPS", as Slicer writes .vtp since 4.11), whose x
// and y are negated to RAS, as the legacy reader does for "SPACE=LPS".
//
// Raw appended data can hold any byte, so the XML parsed is the text before
// <AppendedData>; the arrays are decoded from the mapped file. The whole
// file is decoded when opened (the points are gathered by id), then handed
// out in chunks.
#include <pugixml.hpp>

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>
#include <cstring>
#include <string_view>
#include <unordered_set>

#include "core/byte_order.h"
#include "core/error.h"
#include "core/mapped_file.h"
#include "io/indexed_lines.h"
#include "io/reader.h"
#include "io/vtp_data.h"

namespace fibscope {
namespace {

using vtp::Type;

// Tuples above this in one piece are refused before anything is decoded.
constexpr uint64_t kMaxTuples = uint64_t(1) << 40;
constexpr uint32_t kMaxComponents = 4096;

std::string shown(std::string_view s) {
  std::string out(s.substr(0, 40));
  for (char& c : out)
    if (uint8_t(c) < 0x20 || uint8_t(c) == 0x7f) c = '?';
  return out;
}

// A decoded array: binary bytes in the file's byte order, or ASCII values.
struct Values {
  Type type = Type::kFloat32;
  bool swap = false;
  std::vector<uint8_t> bytes;
  std::vector<double> ascii;
  bool isAscii = false;
  double at(uint64_t i) const { return isAscii ? ascii[i] : vtp::valueAt(bytes.data(), type, swap, i); }
};

class VtpReader final : public TractogramReader {
 public:
  explicit VtpReader(const std::string& path);
  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override {
    const uint64_t lines = line_offsets_.size() - 1;
    return lines == 0 ? file_.size() : file_.size() * next_line_ / lines;
  }

 private:
  void parsePiece(const pugi::xml_node& piece, size_t index);
  Values decode(const pugi::xml_node& array, Type type, std::optional<uint64_t> count, const std::string& what);
  Type arrayType(const pugi::xml_node& array, const std::string& what);
  uint64_t countAttribute(const pugi::xml_node& node, const char* name, const std::string& what, uint64_t max);
  void readSpace(const pugi::xml_node& field_data);
  [[noreturn]] void failNode(const pugi::xml_node& node, const std::string& message) const {
    failAt(header_.path, uint64_t(std::max<ptrdiff_t>(node.offset_debug(), 0)), message);
  }

  MappedFile file_;
  vtp::Encoding encoding_;
  vtp::BinarySource appended_;  // the bytes after "_" in <AppendedData>
  bool have_appended_ = false;
  std::vector<float> points_;
  std::vector<uint64_t> line_offsets_ = {0};
  std::vector<uint64_t> line_ids_;  // into points_ (all pieces)
  std::vector<DataArray> point_arrays_, line_arrays_;
  uint64_t next_line_ = 0;
  bool lps_ = false;
  bool other_cells_warned_ = false;
};

VtpReader::VtpReader(const std::string& path) : file_(path) {
  header_.path = path;
  header_.format = "vtp";
  header_.file_bytes = file_.size();
  const std::string_view text = file_.view();

  // The XML: everything before <AppendedData>, closed again (see above).
  std::string xml;
  const size_t appended_at = text.find("<AppendedData");
  if (appended_at == std::string_view::npos) {
    xml.assign(text);
  } else {
    const size_t tag_end = text.find('>', appended_at);
    if (tag_end == std::string_view::npos) failAt(path, appended_at, "<AppendedData> tag is not closed");
    pugi::xml_document tag;
    const std::string tag_xml = std::string(text.substr(appended_at, tag_end - appended_at)) +
                                (text[tag_end - 1] == '/' ? ">" : "/>");
    if (!tag.load_buffer(tag_xml.data(), tag_xml.size()))
      failAt(path, appended_at, "cannot parse the <AppendedData> tag");
    const std::string encoding = tag.first_child().attribute("encoding").as_string("raw");
    if (encoding != "raw" && encoding != "base64")
      failAt(path, appended_at, "<AppendedData> encoding '" + shown(encoding) + "' (expected raw or base64)");
    const size_t underscore = text.find('_', tag_end);
    if (underscore == std::string_view::npos) failAt(path, tag_end, "<AppendedData> has no '_' before its data");
    appended_.data = file_.data() + underscore + 1;
    appended_.size = file_.size() - underscore - 1;
    appended_.offset = underscore + 1;
    appended_.base64 = encoding == "base64";
    have_appended_ = true;
    xml.assign(text.substr(0, appended_at));
    xml += "</VTKFile>";
    // The raw bytes cannot say where they end, so a cut file would read as
    // far as it goes: the closing tags are what tell it is whole.
    size_t end = text.size();
    while (end > 0 && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
    constexpr std::string_view kClose = "</VTKFile>";
    if (end < kClose.size() || text.substr(end - kClose.size(), kClose.size()) != kClose)
      failAt(path, file_.size(), "the file does not end with </VTKFile>: it is truncated");
  }
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(xml.data(), xml.size());
  if (!parsed) failAt(path, uint64_t(std::max<ptrdiff_t>(parsed.offset, 0)), std::string("not well-formed XML: ") + parsed.description());

  const pugi::xml_node root = doc.child("VTKFile");
  if (!root) fail(path, "no <VTKFile> element: not a VTK XML file");
  const std::string type = root.attribute("type").as_string();
  if (type != "PolyData")
    failNode(root, "a VTK XML '" + shown(type) + "' file; streamlines are read from PolyData (.vtp) files");
  const std::string byte_order = root.attribute("byte_order").as_string("LittleEndian");
  if (byte_order != "LittleEndian" && byte_order != "BigEndian")
    failNode(root, "byte_order '" + shown(byte_order) + "' (expected LittleEndian or BigEndian)");
  encoding_.swap = (byte_order == "BigEndian") == kHostIsLittleEndian;
  const std::string header_type = root.attribute("header_type").as_string("UInt32");
  if (header_type != "UInt32" && header_type != "UInt64")
    failNode(root, "header_type '" + shown(header_type) + "' (expected UInt32 or UInt64)");
  encoding_.header_bytes = header_type == "UInt64" ? 8 : 4;
  const std::string compressor = root.attribute("compressor").as_string();
  if (compressor.empty()) encoding_.compressor = vtp::Compressor::kNone;
  else if (compressor == "vtkZLibDataCompressor") encoding_.compressor = vtp::Compressor::kZlib;
  else if (compressor == "vtkLZ4DataCompressor") encoding_.compressor = vtp::Compressor::kLz4;
  else if (compressor == "vtkLZMADataCompressor") encoding_.compressor = vtp::Compressor::kLzma;
  else failNode(root, "compressor '" + shown(compressor) + "' is not one of VTK's (zlib, LZ4, LZMA)");

  const pugi::xml_node poly = root.child("PolyData");
  if (!poly) failNode(root, "no <PolyData> element");
  header_.properties = {{"vtk.version", root.attribute("version").as_string()},
                        {"vtk.encoding", have_appended_ ? (appended_.base64 ? "appended base64" : "appended raw")
                                                        : "inline"},
                        {"vtk.compressor", compressor.empty() ? "none" : compressor}};
  if (const pugi::xml_node field = poly.child("FieldData")) readSpace(field);
  size_t pieces = 0;
  for (const pugi::xml_node& piece : poly.children("Piece")) parsePiece(piece, pieces++);
  if (pieces == 0) failNode(poly, "<PolyData> has no <Piece>");
  if (line_offsets_.size() == 1) warn("no lines: the file holds no streamlines");
  header_.declared_streamlines = int64_t(line_offsets_.size() - 1);
  header_.declared_points = int64_t(line_offsets_.back());
  for (const auto& a : point_arrays_) header_.per_point.push_back({a.name, a.components, a.dtype, {}});
  for (const auto& a : line_arrays_) header_.per_streamline.push_back({a.name, a.components, a.dtype, {}});
}

uint64_t VtpReader::countAttribute(const pugi::xml_node& node, const char* name, const std::string& what,
                                   uint64_t max) {
  const pugi::xml_attribute a = node.attribute(name);
  if (!a) return 0;
  const std::string s = a.as_string();
  uint64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v > max)
    failNode(node, what + " " + name + " is '" + shown(s) + "'");
  return v;
}

Type VtpReader::arrayType(const pugi::xml_node& array, const std::string& what) {
  const std::string name = array.attribute("type").as_string();
  const auto type = vtp::typeNamed(name);
  if (!type) failNode(array, what + ": type '" + shown(name) + "' is not a VTK XML type");
  return *type;
}

Values VtpReader::decode(const pugi::xml_node& array, Type type, std::optional<uint64_t> count,
                         const std::string& what) {
  Values v;
  v.type = type;
  v.swap = encoding_.swap;
  const std::string format = array.attribute("format").as_string("ascii");
  const uint64_t offset = uint64_t(std::max<ptrdiff_t>(array.offset_debug(), 0));
  const uint64_t bytes_per = vtp::typeBytes(type);
  const uint64_t max_bytes = count ? *count * bytes_per : 4096;  // strings: the SPACE tag only
  if (format == "ascii") {
    v.isAscii = true;
    v.ascii = vtp::parseAscii(array.text().get(), type, count, max_bytes, offset, header_.path, what);
    return v;
  }
  vtp::BinarySource source;
  if (format == "binary") {
    const char* text = array.text().get();
    source.data = reinterpret_cast<const uint8_t*>(text);
    source.size = std::strlen(text);
    source.offset = offset;
    source.base64 = true;
  } else if (format == "appended") {
    if (!have_appended_) failNode(array, what + ": format 'appended' but the file has no <AppendedData>");
    const uint64_t at = countAttribute(array, "offset", what, UINT64_MAX);
    if (!array.attribute("offset")) failNode(array, what + ": format 'appended' without an offset");
    if (at > appended_.size)
      failNode(array, what + ": appended offset " + std::to_string(at) + " is past the end of the file");
    source = appended_;
    source.data += at;
    source.size -= at;
    source.offset += at;
  } else {
    failNode(array, what + ": format '" + shown(format) + "' (expected ascii, binary or appended)");
  }
  v.bytes = vtp::decodeBinary(encoding_, source, count ? std::optional<uint64_t>(*count * bytes_per) : std::nullopt,
                              max_bytes, header_.path, what);
  return v;
}

void VtpReader::readSpace(const pugi::xml_node& field_data) {
  // VTK writes string arrays as <Array> (abstract arrays), numeric ones as
  // <DataArray>.
  for (const pugi::xml_node& array : field_data.children()) {
    const std::string_view element = array.name();
    if ((element != "Array" && element != "DataArray") ||
        std::string_view(array.attribute("Name").as_string()) != "SPACE")
      continue;
    if (arrayType(array, "FieldData 'SPACE'") != Type::kString) return;
    const Values v = decode(array, Type::kString, std::nullopt, "FieldData 'SPACE'");
    std::string space;
    const uint64_t n = v.isAscii ? v.ascii.size() : v.bytes.size();
    for (uint64_t i = 0; i < n && v.at(i) != 0; ++i) space += char(int(v.at(i)));
    header_.properties.emplace_back("vtk.space", shown(space));
    lps_ = space.find("LPS") != std::string::npos;
    return;
  }
}

void VtpReader::parsePiece(const pugi::xml_node& piece, size_t index) {
  const std::string where = "Piece " + std::to_string(index);
  const uint64_t n_points = countAttribute(piece, "NumberOfPoints", where, kMaxTuples);
  const uint64_t n_verts = countAttribute(piece, "NumberOfVerts", where, kMaxTuples);
  const uint64_t n_lines = countAttribute(piece, "NumberOfLines", where, kMaxTuples);
  const uint64_t n_strips = countAttribute(piece, "NumberOfStrips", where, kMaxTuples);
  const uint64_t n_polys = countAttribute(piece, "NumberOfPolys", where, kMaxTuples);
  const uint64_t n_cells = n_verts + n_lines + n_strips + n_polys;
  const uint64_t point_base = points_.size() / 3;

  // Points.
  if (n_points > 0) {
    const pugi::xml_node array = piece.child("Points").child("DataArray");
    if (!array) failNode(piece, where + " has " + std::to_string(n_points) + " points but no <Points> DataArray");
    const std::string what = where + " Points";
    const Type type = arrayType(array, what);
    if (!vtp::isNumeric(type)) failNode(array, what + " must be numeric");
    if (countAttribute(array, "NumberOfComponents", what, kMaxComponents) != 3)
      failNode(array, what + " must have NumberOfComponents=\"3\"");
    const Values v = decode(array, type, 3 * n_points, what);
    points_.resize(3 * (point_base + n_points));
    for (uint64_t i = 0; i < 3 * n_points; ++i) points_[3 * point_base + i] = float(v.at(i));
  }

  // Lines: offsets first (their last value is the connectivity's size).
  if (n_lines > 0) {
    const pugi::xml_node lines = piece.child("Lines");
    pugi::xml_node offsets_node, connectivity_node;
    for (const pugi::xml_node& a : lines.children("DataArray")) {
      const std::string_view name = a.attribute("Name").as_string();
      if (name == "offsets") offsets_node = a;
      if (name == "connectivity") connectivity_node = a;
    }
    if (!offsets_node || !connectivity_node)
      failNode(lines ? lines : piece, where + " has " + std::to_string(n_lines) +
                                          " lines but no 'offsets' and 'connectivity' arrays under <Lines>");
    const std::string what_o = where + " Lines offsets", what_c = where + " Lines connectivity";
    const Type offset_type = arrayType(offsets_node, what_o), id_type = arrayType(connectivity_node, what_c);
    if (!vtp::isIntegral(offset_type)) failNode(offsets_node, what_o + " must have an integer type");
    if (!vtp::isIntegral(id_type)) failNode(connectivity_node, what_c + " must have an integer type");
    const Values offsets = decode(offsets_node, offset_type, n_lines, what_o);
    double previous = 0;
    for (uint64_t i = 0; i < n_lines; ++i) {
      const double o = offsets.at(i);
      if (!(o >= previous) || o > double(kMaxTuples))
        failNode(offsets_node, what_o + ": line " + std::to_string(i) + " ends at " + std::to_string(o) +
                                   (o < previous ? ", before the previous one" : ""));
      previous = o;
    }
    const uint64_t entries = uint64_t(previous);
    const Values ids = decode(connectivity_node, id_type, entries, what_c);
    uint64_t begin = 0;
    line_ids_.reserve(line_ids_.size() + entries);
    for (uint64_t i = 0; i < n_lines; ++i) {
      const uint64_t end = uint64_t(offsets.at(i));
      for (uint64_t j = begin; j < end; ++j) {
        const double id = ids.at(j);
        if (!(id >= 0 && id < double(n_points)))
          failNode(connectivity_node, what_c + ": line " + std::to_string(i) + " refers to point " +
                                          std::to_string(int64_t(id)) + ", but the piece has " +
                                          std::to_string(n_points) + " points");
        line_ids_.push_back(point_base + uint64_t(id));
      }
      line_offsets_.push_back(line_ids_.size());
      begin = end;
    }
  }
  if (n_verts + n_strips + n_polys > 0 && !other_cells_warned_)
    other_cells_warned_ = true, warn(where + ": " + std::to_string(n_verts + n_strips + n_polys) +
         " vertices, strips or polygons skipped (only lines are streamlines)");

  // Per-point and per-line arrays. Every piece must carry the same ones.
  auto gather = [&](const char* section, uint64_t tuples, uint64_t first, uint64_t count,
                    std::vector<DataArray>& arrays) {
    size_t k = 0;
    std::unordered_set<std::string> seen;
    for (const pugi::xml_node& array : piece.child(section).children("DataArray")) {
      std::string name = array.attribute("Name").as_string();
      const std::string what = where + " " + section + " '" + shown(name) + "'";
      const Type type = arrayType(array, what);
      uint64_t components = countAttribute(array, "NumberOfComponents", what, kMaxComponents);
      if (!array.attribute("NumberOfComponents")) components = 1;
      if (!vtp::isNumeric(type) || components == 0) {
        if (index == 0) warn(what + " skipped (not numeric)");
        continue;
      }
      if (name.empty()) name = std::string(section) + "_" + std::to_string(k);
      const std::string base = name;
      for (int n = 2; seen.count(name); ++n) {
        name = base;
        name.push_back('_');
        name.append(std::to_string(n));
      }
      seen.insert(name);
      if (index == 0) {
        arrays.push_back({name, uint32_t(components), vtp::dtypeName(type), {}});
      } else if (k >= arrays.size() || arrays[k].name != name || arrays[k].components != components) {
        failNode(array, what + " differs from Piece 0's arrays (every piece must carry the same ones)");
      }
      const Values v = decode(array, type, tuples * components, what);
      std::vector<float>& out = arrays[k].values;
      for (uint64_t i = first * components; i < (first + count) * components; ++i) out.push_back(float(v.at(i)));
      ++k;
    }
    if (index > 0 && k != arrays.size())
      failNode(piece, where + " " + section + " has " + std::to_string(k) + " arrays, Piece 0 has " +
                          std::to_string(arrays.size()));
  };
  gather("PointData", n_points, 0, n_points, point_arrays_);
  gather("CellData", n_cells, n_verts, n_lines, line_arrays_);
}

bool VtpReader::read(Tractogram& chunk, size_t max_points) {
  startChunk(chunk);
  const uint64_t lines = line_offsets_.size() - 1;
  if (next_line_ >= lines) return false;
  const IndexedPoints src{header_.path, points_, point_arrays_, line_arrays_, lps_};
  while (next_line_ < lines) {
    const uint64_t i = next_line_, begin = line_offsets_[i];
    // Ids were checked against their piece's points when parsed.
    appendIndexedLine(chunk, src, i, line_offsets_[i + 1] - begin, [&](uint64_t j) { return line_ids_[begin + j]; });
    ++next_line_;
    if (chunk.pointCount() >= max_points) break;
  }
  return true;
}

}  // namespace

std::unique_ptr<TractogramReader> openVtp(const std::string& path) { return std::make_unique<VtpReader>(path); }

}  // namespace fibscope
