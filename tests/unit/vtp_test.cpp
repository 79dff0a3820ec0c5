// VTK XML PolyData (.vtp) reader, and both VTK readers against files VTK's
// own writers made (tests/tools/vtk_real_make.py, Debian's python3-vtk9):
// every data mode, compressor, header width and byte order, legacy 4.2 and
// 5.1, Slicer's LPS files; then hand-made malformed files and truncation.
#include <gtest/gtest.h>

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
                    size_t max_points = size_t(1) << 20) {
  return test::readChunked([&] { return openTractogram(path); }, out, warnings, nullptr, max_points);
}

bool pythonHasVtk() {
  return test::runCommand("/usr/bin/python3 -c 'import vtk, numpy' 2>/dev/null").exit_code == 0;
}

void expectArrays(const std::vector<DataArray>& arrays, const Json& want, const std::string& what) {
  EXPECT_EQ(arrays.size(), want.size()) << what;
  for (const auto& [name, spec] : want.items()) {
    const DataArray* found = nullptr;
    for (const auto& a : arrays)
      if (a.name == name) found = &a;
    ASSERT_NE(found, nullptr) << what << " " << name;
    EXPECT_EQ(found->components, spec["components"].get<uint32_t>()) << what << " " << name;
    EXPECT_EQ(found->values, spec["values"].get<std::vector<float>>()) << what << " " << name;
  }
}

TEST(VtkWrittenByVtk, everyDataModeCompressorAndVersionReadsAsVtkReadsIt) {
  if (!pythonHasVtk()) GTEST_SKIP() << "needs /usr/bin/python3 with VTK (Debian's python3-vtk9)";
  TempDir dir;
  const auto r = test::runCommand("/usr/bin/python3 " + test::toolPath("vtk_real_make.py") + " " + dir.path() + " 2>&1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  size_t cases = 0, lps = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    const std::string path = entry.path().string();
    if (entry.path().extension() == ".json") continue;
    SCOPED_TRACE(entry.path().filename().string());
    ++cases;
    const Json want = Json::parse(test::readBytes(std::filesystem::path(path).replace_extension(".json").string()));
    Tractogram t;
    std::vector<std::string> warnings;
    ASSERT_EQ(readAll(path, &t, &warnings, 5), "");
    ASSERT_EQ(t.streamlineCount(), want["streamlines"].size());
    for (size_t s = 0; s < t.streamlineCount(); ++s)
      EXPECT_EQ(std::vector<float>(t.positions.begin() + 3 * t.offsets[s], t.positions.begin() + 3 * t.offsets[s + 1]),
                want["streamlines"][s].get<std::vector<float>>())
          << "streamline " << s;
    expectArrays(t.per_point, want["per_point"], "point data");
    expectArrays(t.per_streamline, want["per_streamline"], "line data");
    lps += want["lps"].get<bool>();
  }
  EXPECT_GE(cases, 30u);  // the script's cases: all of them were read
  EXPECT_EQ(lps, 3u);     // the Slicer-style LPS files were flipped to RAS
}

// --- hand-made files: structure, errors, truncation ---

const char* kAscii = R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="4" NumberOfLines="2">
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0  1 0 0  2 0 0  0 5 0</DataArray>
      </Points>
      <Lines>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3 1</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">3 5</DataArray>
      </Lines>
      <PointData>
        <DataArray type="Float32" Name="fa" format="ascii">0.1 0.2 0.3 0.4</DataArray>
      </PointData>
      <CellData>
        <DataArray type="Int32" Name="bundle" format="ascii">7 9</DataArray>
      </CellData>
    </Piece>
  </PolyData>
</VTKFile>
)";

std::string withReplaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string errorOf(const std::string& text) {
  TempDir dir;
  test::writeBytes(dir.file("t.vtp"), text);
  return readAll(dir.file("t.vtp"));
}

TEST(VtpReader, readsAHandWrittenAsciiFile) {
  TempDir dir;
  test::writeBytes(dir.file("t.vtp"), kAscii);
  Tractogram t;
  ASSERT_EQ(readAll(dir.file("t.vtp"), &t), "");
  ASSERT_EQ(t.streamlineCount(), 2u);
  EXPECT_EQ(t.positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 5, 0, 1, 0, 0}));
  ASSERT_EQ(t.per_point.size(), 1u);
  EXPECT_EQ(t.per_point[0].values, (std::vector<float>{0.1f, 0.2f, 0.3f, 0.4f, 0.2f}));
  ASSERT_EQ(t.per_streamline.size(), 1u);
  EXPECT_EQ(t.per_streamline[0].values, (std::vector<float>{7, 9}));
}

TEST(VtpReader, malformedFilesGetOneLineNamingTheProblem) {
  const std::pair<std::string, std::string> cases[] = {
      {withReplaced(kAscii, "type=\"PolyData\"", "type=\"UnstructuredGrid\""), "'UnstructuredGrid' file"},
      {withReplaced(kAscii, "</Piece>", ""), "not well-formed XML"},
      {withReplaced(kAscii, "0 1 2 3 1", "0 1 2 3 9"), "refers to point 9"},
      {withReplaced(kAscii, "3 5</DataArray>", "5 3</DataArray>"), "before the previous one"},
      {withReplaced(kAscii, "0.1 0.2 0.3 0.4", "0.1 0.2 0.3"), "3 ASCII values, expected 4"},
      {withReplaced(kAscii, "0.1 0.2 0.3 0.4", "0.1 x 0.3 0.4"), "'x' is not a number"},
      {withReplaced(kAscii, "NumberOfPoints=\"4\"", "NumberOfPoints=\"99999999999999999\""), "NumberOfPoints"},
      {withReplaced(kAscii, "NumberOfComponents=\"3\"", "NumberOfComponents=\"2\""), "NumberOfComponents=\"3\""},
      {withReplaced(kAscii, "type=\"Int64\" Name=\"offsets\"", "type=\"Float32\" Name=\"offsets\""), "integer type"},
      {withReplaced(kAscii, "type=\"Float32\" Name=\"fa\"", "type=\"Quad\" Name=\"fa\""), "'Quad' is not a VTK XML type"},
      {withReplaced(kAscii, "byte_order=\"LittleEndian\"", "byte_order=\"Middle\""), "byte_order 'Middle'"},
      {withReplaced(kAscii, "byte_order=", "compressor=\"vtkFooCompressor\" byte_order="), "compressor 'vtkFooCompressor'"},
      {withReplaced(kAscii, "format=\"ascii\">0 0 0", "format=\"appended\" offset=\"0\">0 0 0"), "no <AppendedData>"},
      {withReplaced(kAscii, "format=\"ascii\">0 0 0  1 0 0  2 0 0  0 5 0", "format=\"binary\">AAAA!!!!"),
       "not base64"},
      // A UInt32 header of 48 bytes (4 points x 3 floats), then no data.
      {withReplaced(kAscii, "format=\"ascii\">0 0 0  1 0 0  2 0 0  0 5 0", "format=\"binary\">MAAAAA=="),
       "Points: data needs 48 bytes, more than remain"},
      {withReplaced(kAscii, "format=\"ascii\">0 0 0  1 0 0  2 0 0  0 5 0", "format=\"binary\">QAAAAA=="),
       "says 64 bytes, its tuples need 48"},
  };
  for (size_t i = 0; i < std::size(cases); ++i) {
    const std::string e = errorOf(cases[i].first);
    EXPECT_NE(e.find(cases[i].second), std::string::npos) << i << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_EQ(e.rfind(std::filesystem::path(e.substr(0, e.find(':'))).string(), 0), 0u) << e;
  }
}

// Every prefix of a real file fails with a message: never a crash, and
// never a silent read of what is left (an appended file must end with
// </VTKFile>, an inline one is not well-formed XML when cut).
TEST(VtpReader, everyTruncatedPrefixOfARealFileFailsCleanly) {
  if (!pythonHasVtk()) GTEST_SKIP() << "needs /usr/bin/python3 with VTK (Debian's python3-vtk9)";
  TempDir dir;
  const auto r = test::runCommand("/usr/bin/python3 " + test::toolPath("vtk_real_make.py") + " " + dir.path() + " 2>&1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* name : {"appended_zlib_u64_raw.vtp", "binary_lz4_u32.vtp", "appended_lzma_u32.vtp"}) {
    SCOPED_TRACE(name);
    const std::string bytes = test::readBytes(dir.file(name));
    ASSERT_EQ(readAll(dir.file(name)), "");
    const std::string cut = dir.file("cut.vtp");
    for (size_t n = 0; n < bytes.size(); n += std::max<size_t>(1, bytes.size() / 400)) {
      test::writeBytes(cut, bytes.substr(0, n));
      const std::string e = readAll(cut);
      EXPECT_NE(e, "") << "prefix " << n << " of " << bytes.size() << " read without an error";
    }
  }
}

// An empty appended raw array (a UInt32 header of 0, no bytes): read as
// empty, not a copy from a null pointer (found by fuzz_vtp under UBSan).
TEST(VtpReader, emptyAppendedArraysReadAsEmpty) {
  const std::string text = std::string(
      "<VTKFile type=\"PolyData\" byte_order=\"LittleEndian\"><PolyData><Piece NumberOfPoints=\"0\">"
      "<PointData><DataArray type=\"Float32\" Name=\"fa\" format=\"appended\" offset=\"0\"/></PointData>"
      "</Piece></PolyData><AppendedData encoding=\"raw\">_") + std::string(4, '\0') + "</AppendedData></VTKFile>";
  TempDir dir;
  test::writeBytes(dir.file("e.vtp"), text);
  Tractogram t;
  ASSERT_EQ(readAll(dir.file("e.vtp"), &t), "");
  EXPECT_EQ(t.streamlineCount(), 0u);
}

TEST(VtpReader, openTractogramDispatchesVtpByExtension) {
  TempDir dir;
  test::writeBytes(dir.file("x.VTP"), kAscii);
  EXPECT_EQ(readTractogram(dir.file("x.VTP")).streamlineCount(), 2u);
}

}  // namespace
}  // namespace fibscope
