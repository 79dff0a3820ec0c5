// Legacy VTK PolyData reader: hand-written ASCII files, binary files written
// from the spec by tests/tools/vtk_make.py, malformed input, truncation.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/reader.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::TempDir;
using Json = nlohmann::json;

std::string readAll(const std::string& path, Tractogram* out = nullptr, std::vector<std::string>* warnings = nullptr,
                    TractogramHeader* header = nullptr, size_t max_points = size_t(1) << 20) {
  return test::readChunked([&] { return openVtk(path); }, out, warnings, header, max_points);
}

std::string save(const TempDir& dir, const std::string& text, const std::string& name = "t.vtk") {
  test::writeBytes(dir.file(name), text);
  return dir.file(name);
}

bool anyContains(const std::vector<std::string>& lines, const std::string& needle) {
  for (const auto& l : lines)
    if (l.find(needle) != std::string::npos) return true;
  return false;
}

// Big-endian bytes of a value (legacy binary VTK).
template <typename T>
std::string be(T v) {
  std::string s(sizeof(T), '\0');
  std::memcpy(s.data(), &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::little) std::reverse(s.begin(), s.end());
  return s;
}

const char* kClassicAscii =
    "# vtk DataFile Version 3.0\n"
    "two streamlines\n"
    "ASCII\n"
    "DATASET POLYDATA\n"
    "POINTS 5 float\n"
    "0 0 0  1 0 0  2 0 0\n"
    "0 5 0  0 6 0\n"
    "LINES 2 7\n"
    "3 0 1 2\n"
    "2 4 3\n"
    "POINT_DATA 5\n"
    "SCALARS fa float 1\n"
    "LOOKUP_TABLE default\n"
    "0.1 0.2 0.3 0.4 0.5\n"
    "VECTORS dir float\n"
    "1 0 0 1 0 0 1 0 0 0 -1 0 0 -1 0\n"
    "CELL_DATA 2\n"
    "SCALARS bundle int\n"
    "LOOKUP_TABLE default\n"
    "7 9\n";

TEST(VtkReader, readsHandWrittenClassicAsciiFile) {
  TempDir dir;
  Tractogram t;
  std::vector<std::string> warnings;
  TractogramHeader h;
  ASSERT_EQ(readAll(save(dir, kClassicAscii), &t, &warnings, &h), "");
  EXPECT_TRUE(warnings.empty()) << ::testing::PrintToString(warnings);
  EXPECT_EQ(t.offsets, (std::vector<uint64_t>{0, 3, 5}));
  // The second line visits points 4 then 3: gathered by index.
  EXPECT_EQ(t.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 6, 0, 0, 5, 0}));
  ASSERT_EQ(t.per_point.size(), 2u);
  EXPECT_EQ(t.per_point[0].name, "fa");
  EXPECT_EQ(t.per_point[0].values, (std::vector<float>{0.1f, 0.2f, 0.3f, 0.5f, 0.4f}));
  EXPECT_EQ(t.per_point[1].name, "dir");
  EXPECT_EQ(t.per_point[1].components, 3u);
  EXPECT_EQ(t.per_point[1].values[9], 0.0f);
  EXPECT_EQ(t.per_point[1].values[10], -1.0f);
  ASSERT_EQ(t.per_streamline.size(), 1u);
  EXPECT_EQ(t.per_streamline[0].name, "bundle");
  EXPECT_EQ(t.per_streamline[0].values, (std::vector<float>{7, 9}));
  EXPECT_EQ(h.format, "vtk");
  EXPECT_EQ(h.declared_streamlines, 2);
  EXPECT_EQ(h.declared_points, 5);
  EXPECT_EQ(h.property("vtk.title"), "two streamlines");
  EXPECT_FALSE(h.space.known);
}

TEST(VtkReader, convertsSlicerLpsFilesToRas) {
  TempDir dir;
  const std::string text =
      "# vtk DataFile Version 4.1\n3D Slicer output. SPACE=LPS\nASCII\nDATASET POLYDATA\n"
      "POINTS 2 float\n1 2 3 -4 -5 6\nLINES 1 3\n2 0 1\n";
  Tractogram t;
  TractogramHeader h;
  ASSERT_EQ(readAll(save(dir, text), &t, nullptr, &h), "");
  EXPECT_EQ(t.positions, (std::vector<float>{-1, -2, 3, 4, 5, 6}));
  EXPECT_EQ(h.property("vtk.space"), "LPS");
  std::string ras = text;
  ras.replace(ras.find("LPS"), 3, "RAS");
  ASSERT_EQ(readAll(save(dir, ras, "ras.vtk"), &t), "");
  EXPECT_EQ(t.positions, (std::vector<float>{1, 2, 3, -4, -5, 6}));
}

TEST(VtkReader, chunksHoldWholeStreamlines) {
  TempDir dir;
  auto reader = openVtk(save(dir, kClassicAscii));
  Tractogram chunk;
  std::vector<size_t> sizes;
  while (reader->read(chunk, 1)) sizes.push_back(chunk.streamlineCount());
  EXPECT_EQ(sizes, (std::vector<size_t>{1, 1}));
  EXPECT_EQ(reader->bytesRead(), std::string(kClassicAscii).size());
}

TEST(VtkReader, skipsPolygonsAndKeepsTheLinesCellData) {
  TempDir dir;
  const std::string text =
      "# vtk DataFile Version 3.0\nmixed\nASCII\nDATASET POLYDATA\n"
      "POINTS 4 float\n0 0 0 1 0 0 1 1 0 0 1 0\n"
      "LINES 1 3\n2 0 2\n"
      "POLYGONS 1 5\n4 0 1 2 3\n"
      "CELL_DATA 2\nSCALARS area float\nLOOKUP_TABLE default\n1 2\n";
  Tractogram t;
  std::vector<std::string> warnings;
  ASSERT_EQ(readAll(save(dir, text), &t, &warnings), "");
  EXPECT_EQ(t.streamlineCount(), 1u);
  // Cells are numbered verts, lines, polys, strips: the line is row 0.
  ASSERT_EQ(t.per_streamline.size(), 1u);
  EXPECT_EQ(t.per_streamline[0].values, std::vector<float>{1.0f});
  EXPECT_EQ(warnings.size(), 1u) << ::testing::PrintToString(warnings);
  EXPECT_TRUE(anyContains(warnings, "1 polygons cells"));
}

TEST(VtkReader, readsBinaryClassicFileBuiltByHand) {
  TempDir dir;
  std::string s = "# vtk DataFile Version 3.0\nbinary\nBINARY\nDATASET POLYDATA\nPOINTS 3 double\n";
  for (double v : {1.5, 2.5, 3.5, -1.0, -2.0, -3.0, 10.0, 20.0, 30.0}) s += be(v);
  s += "\nLINES 1 3\n" + be<int32_t>(2) + be<int32_t>(2) + be<int32_t>(0) + "\n";
  Tractogram t;
  ASSERT_EQ(readAll(save(dir, s), &t), "");
  EXPECT_EQ(t.positions, (std::vector<float>{10, 20, 30, 1.5f, 2.5f, 3.5f}));
}

// --- malformed input: one-line errors naming the file and where ---

void expectError(const std::string& text, const std::string& needle) {
  TempDir dir;
  const std::string path = save(dir, text);
  const std::string e = readAll(path);
  ASSERT_FALSE(e.empty()) << "expected an error containing '" << needle << "'";
  EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_NE(e.find(needle), std::string::npos) << e;
}

const char* kHead = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\n";

TEST(VtkReader, rejectsMissingVersionLine) { expectError("# not vtk\nt\nASCII\n", "byte 0: expected '# vtk DataFile"); }

TEST(VtkReader, rejectsOtherDatasets) {
  expectError("# vtk DataFile Version 3.0\nt\nASCII\nDATASET UNSTRUCTURED_GRID\n", "expected DATASET POLYDATA");
}

TEST(VtkReader, rejectsUnknownEncoding) { expectError("# vtk DataFile Version 3.0\nt\nXML\n", "expected ASCII or BINARY"); }

TEST(VtkReader, rejectsWrongKeyword) {
  expectError(std::string(kHead) + "POINTS 1 float\n0 0 0\nLINEZ 1 2\n1 0\n", "byte 73: unexpected keyword 'LINEZ'");
}

TEST(VtkReader, rejectsIndexOutOfRangeWithItsOffset) {
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 2\n", "refers to point 2, but POINTS has 2");
  std::string s = "# vtk DataFile Version 3.0\nb\nBINARY\nDATASET POLYDATA\nPOINTS 1 float\n";
  for (int i = 0; i < 3; ++i) s += be(0.0f);
  s += "\nLINES 1 3\n";
  const size_t entry = s.size() + 8;  // the second id of the cell
  s += be<int32_t>(2) + be<int32_t>(0) + be<int32_t>(-4) + "\n";
  expectError(s, "byte " + std::to_string(entry) + ": line 0 point 1 refers to point -4");
}

TEST(VtkReader, rejectsCellSizesThatDisagreeWithTheSection) {
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nLINES 1 4\n2 0 1\n", "LINES declares 4 entries");
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n5 0 1\n", "cell 0 has 5 points");
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nLINES 3 2\n1 0 1 1\n", "cannot fit");
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nLINES 3 4\n1 0 1 1\n", "end before cell 2");
  // The same in binary, where reading on would leave the section (found by fuzz_vtk).
  std::string binary = "# vtk DataFile Version 3.0\nb\nBINARY\nDATASET POLYDATA\nPOINTS 1 float\n";
  for (int i = 0; i < 3; ++i) binary += be(0.0f);
  binary += "\nLINES 3 4\n" + be<int32_t>(1) + be<int32_t>(0) + be<int32_t>(1) + be<int32_t>(0);
  expectError(binary, "end before cell 2");
}

TEST(VtkReader, rejectsBadVersion51Offsets) {
  expectError(std::string(kHead) +
                  "POINTS 2 float\n0 0 0 1 1 1\nLINES 2 2\nOFFSETS vtktypeint64\n1 2\nCONNECTIVITY vtktypeint64\n0 1\n",
              "OFFSETS must start at 0");
  expectError(std::string(kHead) +
                  "POINTS 2 float\n0 0 0 1 1 1\nLINES 2 3\nOFFSETS vtktypeint64\n0 2\nCONNECTIVITY vtktypeint64\n0 1 1\n",
              "OFFSETS end at 2");
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nLINES 2 2\nOFFSETS vtktypeint64\n0 2\nCONNECT int\n0 1\n",
              "expected connectivity");
}

// Found by fuzz_vtk: a string-typed CONNECTIVITY in a binary file was sized
// by dividing by its element size, which is 0.
TEST(VtkReader, rejectsNonIntegerConnectivityInBinaryFiles) {
  expectError(std::string("# vtk DataFile Version 5.1\nt\nBINARY\nDATASET POLYDATA\nPOINTS 0 float\n\n"
                          "LINES 1 0\nOFFSETS vtktypeint64\n") +
                  std::string(8, '\0') + "\nCONNECTIVITY string\n",
              "CONNECTIVITY must have an integer type");
}

TEST(VtkReader, rejectsAbsurdCountsBeforeAllocating) {
  expectError(std::string(kHead) + "POINTS 99999999999 float\n0 0 0\n", "POINTS");
  expectError(std::string(kHead) + "POINTS 1 float\n0 0 0\nLINES 1 99999999999\n", "LINES");
  expectError(std::string(kHead) + "POINTS -3 float\n", "expected a non-negative count for POINTS, found '-3'");
}

TEST(VtkReader, rejectsBadNumbersAndTypes) {
  expectError(std::string(kHead) + "POINTS 1 float\n0 zero 0\n", "POINTS: value 1 is 'zero', expected a number");
  expectError(std::string(kHead) + "POINTS 1 quad\n0 0 0\n", "unknown data type 'quad'");
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0\n", "POINTS: file ends after 3 of 6 values");
}

TEST(VtkReader, rejectsAttributeCountsThatDisagree) {
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nPOINT_DATA 3\n", "POINT_DATA has 3 values, POINTS has 2");
  expectError(std::string(kHead) + "POINTS 2 float\n0 0 0 1 1 1\nLINES 1 3\n2 0 1\nCELL_DATA 2\n",
              "CELL_DATA has 2 values, the file has 1 cells");
  expectError(std::string(kHead) + "POINTS 1 float\n0 0 0\nSCALARS a float\n1\n", "before POINT_DATA or CELL_DATA");
}

TEST(VtkReader, everyTruncatedPrefixThrowsOrReadsAConsistentPrefix) {
  TempDir dir;
  std::string binary = "# vtk DataFile Version 3.0\nb\nBINARY\nDATASET POLYDATA\nPOINTS 3 float\n";
  for (int i = 0; i < 9; ++i) binary += be(float(i));
  binary += "\nLINES 2 5\n" + be<int32_t>(2) + be<int32_t>(0) + be<int32_t>(1) + be<int32_t>(1) + be<int32_t>(2);
  binary += "\nPOINT_DATA 3\nSCALARS fa float\nLOOKUP_TABLE default\n" + be(0.5f) + be(0.25f) + be(0.125f) + "\n";
  for (const std::string& full : {std::string(kClassicAscii), binary}) {
    for (size_t n = 0; n < full.size(); ++n) {
      const std::string path = dir.file("prefix" + std::to_string(n) + ".vtk");
      test::writeBytes(path, full.substr(0, n));
      Tractogram t;
      const std::string e = readAll(path, &t);
      if (!e.empty()) {
        EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
      } else {
        EXPECT_EQ(t.validate(), "") << n;
        EXPECT_LE(t.streamlineCount(), 2u) << n;
      }
      std::filesystem::remove(path);
    }
  }
}

// --- files written from the spec by tests/tools/vtk_make.py ---

TEST(VtkSpec, readsBinaryAndVersion51FilesWrittenFromTheSpec) {
  const std::string python = test::pythonWithNibabel();
  if (python.empty()) GTEST_SKIP() << "needs /usr/bin/python3 with numpy";
  TempDir dir;
  const auto r = test::runCommand(python + " " + test::toolPath("vtk_make.py") + " " + dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* name : {"binary_classic", "binary_51", "ascii_51", "binary_with_vertices"}) {
    SCOPED_TRACE(name);
    const Json expected = Json::parse(test::readBytes(dir.file(std::string(name) + ".json")));
    Tractogram t;
    std::vector<std::string> warnings;
    ASSERT_EQ(readAll(dir.file(std::string(name) + ".vtk"), &t, &warnings, nullptr, 7), "");
    ASSERT_EQ(t.streamlineCount(), expected["streamlines"].size());
    for (size_t s = 0; s < t.streamlineCount(); ++s) {
      const std::vector<float> want = expected["streamlines"][s].get<std::vector<float>>();
      EXPECT_EQ(std::vector<float>(t.positions.begin() + 3 * t.offsets[s], t.positions.begin() + 3 * t.offsets[s + 1]),
                want)
          << "streamline " << s;
    }
    auto compare = [](const std::vector<DataArray>& arrays, const Json& want) {
      EXPECT_EQ(arrays.size(), want.size());
      for (const auto& [array_name, spec] : want.items()) {
        const DataArray* found = nullptr;
        for (const auto& a : arrays)
          if (a.name == array_name) found = &a;
        ASSERT_NE(found, nullptr) << array_name;
        EXPECT_EQ(found->components, spec["components"].get<uint32_t>()) << array_name;
        EXPECT_EQ(found->values, spec["values"].get<std::vector<float>>()) << array_name;
      }
    };
    compare(t.per_point, expected["per_point"]);
    compare(t.per_streamline, expected["per_streamline"]);
    for (const auto& w : expected["warnings"]) EXPECT_TRUE(anyContains(warnings, w.get<std::string>())) << w;
    EXPECT_EQ(warnings.size(), expected["warnings"].size()) << ::testing::PrintToString(warnings);
  }
}

TEST(VtkSpec, openTractogramDispatchesVtkByExtension) {
  TempDir dir;
  const std::string path = save(dir, kClassicAscii, "x.VTK");
  EXPECT_EQ(readTractogram(path).streamlineCount(), 2u);
}

}  // namespace
}  // namespace fibscope
