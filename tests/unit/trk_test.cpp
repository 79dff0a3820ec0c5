// TrackVis .trk reader and writer: values against nibabel, hand-built files
// from the spec, malformed input, round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>

#include "core/error.h"
#include "io/reader.h"
#include "io/trk_format.h"
#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::TempDir;
using Json = nlohmann::json;

// A .trk file built byte by byte at the offsets of the TrackVis spec
// (independent of io/trk_format), little-endian.
class TrkBytes {
 public:
  TrkBytes() : bytes_(1000, '\0') {
    std::memcpy(bytes_.data(), "TRACK", 5);
    for (int k = 0; k < 3; ++k) {
      put<int16_t>(6 + 2 * k, 10);
      put<float>(12 + 4 * k, 1.0f);
    }
    for (int i = 0; i < 4; ++i) put<float>(440 + 4 * (5 * i), 1.0f);  // identity vox_to_ras
    std::memcpy(bytes_.data() + 948, "RAS", 3);
    put<int32_t>(992, 2);
    put<int32_t>(996, 1000);
  }
  template <typename T>
  void put(size_t offset, T value) {
    if (bytes_.size() < offset + sizeof(T)) bytes_.resize(offset + sizeof(T));
    std::memcpy(bytes_.data() + offset, &value, sizeof(T));
  }
  void scalarName(int i, const std::string& raw) { std::memcpy(bytes_.data() + 38 + 20 * i, raw.data(), raw.size()); }
  void propertyName(int i, const std::string& raw) {
    std::memcpy(bytes_.data() + 240 + 20 * i, raw.data(), raw.size());
  }
  void counts(int16_t scalars, int16_t properties, int32_t streamlines) {
    put<int16_t>(36, scalars);
    put<int16_t>(238, properties);
    put<int32_t>(988, streamlines);
  }
  // Appends int32 m, then the point records (x y z scalars...) and properties.
  void streamline(int32_t m, const std::vector<float>& records, const std::vector<float>& properties = {}) {
    put<int32_t>(bytes_.size(), m);
    for (float v : records) put<float>(bytes_.size(), v);
    for (float v : properties) put<float>(bytes_.size(), v);
  }
  std::string& bytes() { return bytes_; }
  std::string save(const TempDir& dir, const std::string& name = "t.trk") const {
    const std::string path = dir.file(name);
    test::writeBytes(path, bytes_);
    return path;
  }

 private:
  std::string bytes_;
};

// Three streamlines, one scalar "fa" and one property "w", count 3.
TrkBytes smallTrk() {
  TrkBytes t;
  t.counts(1, 1, 3);
  t.scalarName(0, "fa");
  t.propertyName(0, "w");
  t.streamline(2, {1, 2, 3, 0.5f, 4, 5, 6, 0.25f}, {7});
  t.streamline(1, {8, 9, 10, 0.125f}, {8});
  t.streamline(3, {1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3}, {9});
  return t;
}

// Reads a whole file, returning the error message ("" when none).
std::string readAll(const std::string& path, Tractogram* out = nullptr, std::vector<std::string>* warnings = nullptr,
                    TractogramHeader* header = nullptr) {
  try {
    auto reader = openTrk(path);
    Tractogram all, chunk;
    while (reader->read(chunk)) all.append(chunk);
    if (out) *out = all;
    if (warnings) *warnings = reader->warnings();
    if (header) *header = reader->header();
    return {};
  } catch (const Error& e) {
    return e.what();
  }
}

bool anyContains(const std::vector<std::string>& lines, const std::string& needle) {
  for (const auto& l : lines)
    if (l.find(needle) != std::string::npos) return true;
  return false;
}

const DataArray* findArray(const std::vector<DataArray>& arrays, const std::string& name) {
  for (const auto& a : arrays)
    if (a.name == name) return &a;
  return nullptr;
}

// Compares a tractogram to what nibabel read (points within `tolerance` mm,
// data arrays exactly).
void expectMatchesNibabel(const Tractogram& t, const Json& ref, double tolerance = 1e-4) {
  ASSERT_EQ(t.validate(), "");
  const auto& streamlines = ref["streamlines"];
  ASSERT_EQ(t.streamlineCount(), streamlines.size());
  double worst = 0;
  for (size_t s = 0; s < streamlines.size(); ++s) {
    ASSERT_EQ(3 * t.pointsIn(s), streamlines[s].size()) << "streamline " << s;
    for (size_t i = 0; i < streamlines[s].size(); ++i)
      worst = std::max(worst, std::fabs(double(t.positions[3 * t.offsets[s] + i]) - streamlines[s][i].get<double>()));
  }
  EXPECT_LE(worst, tolerance);
  for (const auto& [name, per_streamline] : ref["data_per_point"].items()) {
    const DataArray* a = findArray(t.per_point, name);
    ASSERT_NE(a, nullptr) << "per-point array " << name;
    std::vector<float> expected;
    for (const auto& values : per_streamline)
      for (const auto& v : values) expected.push_back(v.get<float>());
    EXPECT_EQ(a->values, expected) << name;
  }
  for (const auto& [name, rows] : ref["data_per_streamline"].items()) {
    const DataArray* a = findArray(t.per_streamline, name);
    ASSERT_NE(a, nullptr) << "per-streamline array " << name;
    std::vector<float> expected;
    for (const auto& row : rows)
      for (const auto& v : row) expected.push_back(v.get<float>());
    EXPECT_EQ(a->values, expected) << name;
    EXPECT_EQ(a->components, rows[0].size()) << name;
  }
  EXPECT_EQ(t.per_point.size(), ref["data_per_point"].size());
  EXPECT_EQ(t.per_streamline.size(), ref["data_per_streamline"].size());
}

// ---------------------------------------------------------------------------
// Against nibabel: files written by nibabel (tests/tools/trk_reference.py).

class TrkNibabel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    python_ = test::pythonWithNibabel();
    if (python_.empty()) return;
    dir_ = new TempDir;
    const auto r = test::runCommand(python_ + " " + test::toolPath("trk_reference.py") + " make " + dir_->path());
    made_ = r.exit_code == 0;
    make_output_ = r.output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (python_.empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel and numpy";
    ASSERT_TRUE(made_) << make_output_;
  }
  static std::string file(const std::string& name) { return dir_->file(name); }
  static Json reference(const std::string& json_path) {
    return Json::parse(test::readBytes(json_path));
  }
  static Json dump(const std::string& trk_path) {
    const std::string json_path = trk_path + ".json";
    const auto r = test::runCommand(python_ + " " + test::toolPath("trk_reference.py") + " dump " + trk_path + " " +
                                    json_path);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return reference(json_path);
  }

  static inline std::string python_;
  static inline TempDir* dir_ = nullptr;
  static inline bool made_ = false;
  static inline std::string make_output_;
};

TEST_F(TrkNibabel, readerMatchesNibabelPointsAndData) {
  for (const char* name : {"oblique_lps", "permuted_las", "identity_ras", "oblique_lps_big", "oblique_lps_v1"}) {
    SCOPED_TRACE(name);
    Tractogram t;
    TractogramHeader h;
    ASSERT_EQ(readAll(file(std::string(name) + ".trk"), &t, nullptr, &h), "");
    const Json ref = reference(file(std::string(name) + ".json"));
    expectMatchesNibabel(t, ref);
    EXPECT_EQ(h.declared_streamlines, ref["n_count"].get<int64_t>());
  }
}

TEST_F(TrkNibabel, readerKeepsTheVoxelGridInSpace) {
  TractogramHeader h;
  ASSERT_EQ(readAll(file("oblique_lps.trk"), nullptr, nullptr, &h), "");
  const Json ref = reference(file("oblique_lps.json"));
  EXPECT_TRUE(h.space.known);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(h.space.voxel_to_rasmm[i], ref["vox_to_ras"][i].get<float>()) << i;
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(h.space.dimensions[k], ref["dimensions"][k].get<int>());
    EXPECT_EQ(h.space.voxel_sizes[k], ref["voxel_sizes"][k].get<float>());
  }
  EXPECT_EQ(h.space.voxel_order, "LPS");
  EXPECT_EQ(h.format, "trk");
  EXPECT_EQ(h.property("trk.byte_order"), "little");
}

TEST_F(TrkNibabel, bigEndianFileReadsLikeLittleEndian) {
  Tractogram little, big;
  TractogramHeader h;
  ASSERT_EQ(readAll(file("oblique_lps.trk"), &little), "");
  ASSERT_EQ(readAll(file("oblique_lps_big.trk"), &big, nullptr, &h), "");
  EXPECT_EQ(big.positions, little.positions);
  EXPECT_EQ(big.offsets, little.offsets);
  EXPECT_EQ(h.property("trk.byte_order"), "big");
}

TEST_F(TrkNibabel, versionOneFallsBackToIdentityWithAWarning) {
  std::vector<std::string> warnings;
  ASSERT_EQ(readAll(file("oblique_lps_v1.trk"), nullptr, &warnings), "");
  EXPECT_TRUE(anyContains(warnings, "version 1")) << ::testing::PrintToString(warnings);
}

TEST_F(TrkNibabel, writerOutputOfANibabelFileReadsBackInNibabel) {
  for (const char* name : {"oblique_lps", "permuted_las", "identity_ras"}) {
    SCOPED_TRACE(name);
    Tractogram t;
    TractogramHeader h;
    ASSERT_EQ(readAll(file(std::string(name) + ".trk"), &t, nullptr, &h), "");
    const std::string out = file(std::string(name) + "_ours.trk");
    std::vector<std::string> warnings;
    writeTractogram(out, t, h, {}, &warnings);
    EXPECT_TRUE(warnings.empty()) << ::testing::PrintToString(warnings);
    const Json back = dump(out);
    expectMatchesNibabel(t, back);                                      // nibabel reads what we wrote
    expectMatchesNibabel(t, reference(file(std::string(name) + ".json")));  // and that is the original
    EXPECT_EQ(back["voxel_order"].get<std::string>(), h.space.voxel_order);
    EXPECT_EQ(back["n_count"].get<int64_t>(), int64_t(t.streamlineCount()));
  }
}

TEST_F(TrkNibabel, writerOutputOfSyntheticDataReadsBackInNibabel) {
  TractogramHeader like;
  ASSERT_EQ(readAll(file("permuted_las.trk"), nullptr, nullptr, &like), "");
  Tractogram t = test::smallTractogram(40, 7, true);
  t.per_point.push_back({"dir", 3, "float32", {}});
  for (size_t i = 0; i < 3 * t.pointCount(); ++i) t.per_point.back().values.push_back(float(i % 17) - 8.5f);
  like.per_point = {{"fa", 1, "float32", {}}, {"dir", 3, "float32", {}}};
  like.per_streamline = {{"weight", 1, "float32", {}}};
  const std::string out = file("synthetic_ours.trk");
  writeTractogram(out, t, like);
  const Json back = dump(out);
  // nibabel reads our points within 1e-4 mm and our data arrays exactly.
  expectMatchesNibabel(t, back);
  EXPECT_EQ(back["data_per_point"]["dir"][0].size(), 3 * t.pointsIn(0));
}

TEST_F(TrkNibabel, roundTripKeepsGridPropertiesAndData) {
  Tractogram first, second;
  TractogramHeader h1, h2;
  ASSERT_EQ(readAll(file("oblique_lps_big.trk"), &first, nullptr, &h1), "");
  const std::string out = file("round_trip.trk");
  writeTractogram(out, first, h1);
  ASSERT_EQ(readAll(out, &second, nullptr, &h2), "");
  EXPECT_EQ(h2.space.voxel_to_rasmm, h1.space.voxel_to_rasmm);
  EXPECT_EQ(h2.space.dimensions, h1.space.dimensions);
  EXPECT_EQ(h2.space.voxel_sizes, h1.space.voxel_sizes);
  EXPECT_EQ(h2.space.voxel_order, h1.space.voxel_order);
  EXPECT_EQ(h2.property("trk.origin"), h1.property("trk.origin"));
  EXPECT_EQ(h2.property("trk.byte_order"), "little");
  ASSERT_EQ(second.offsets, first.offsets);
  double worst = 0;
  for (size_t i = 0; i < first.positions.size(); ++i)
    worst = std::max(worst, std::fabs(double(first.positions[i]) - second.positions[i]));
  EXPECT_LE(worst, 1e-4);
  ASSERT_EQ(second.per_point.size(), first.per_point.size());
  for (size_t i = 0; i < first.per_point.size(); ++i) EXPECT_EQ(second.per_point[i].values, first.per_point[i].values);
  ASSERT_EQ(second.per_streamline.size(), first.per_streamline.size());
  for (size_t i = 0; i < first.per_streamline.size(); ++i)
    EXPECT_EQ(second.per_streamline[i].values, first.per_streamline[i].values);
}

// ---------------------------------------------------------------------------
// Hand-built files.

TEST(TrkReader, readsHandBuiltFileWithScalarsAndProperties) {
  TempDir dir;
  Tractogram t;
  std::vector<std::string> warnings;
  TractogramHeader h;
  ASSERT_EQ(readAll(smallTrk().save(dir), &t, &warnings, &h), "");
  EXPECT_TRUE(warnings.empty()) << ::testing::PrintToString(warnings);
  ASSERT_EQ(t.offsets, (std::vector<uint64_t>{0, 2, 3, 6}));
  // Identity grid, 1 mm voxels: RAS = voxmm - 0.5 (voxel corner -> centre).
  EXPECT_EQ(t.positions[0], 0.5f);
  EXPECT_EQ(t.positions[5], 5.5f);
  EXPECT_EQ(t.positions[8], 9.5f);
  ASSERT_EQ(t.per_point.size(), 1u);
  EXPECT_EQ(t.per_point[0].name, "fa");
  EXPECT_EQ(t.per_point[0].values, (std::vector<float>{0.5f, 0.25f, 0.125f, 1, 2, 3}));
  ASSERT_EQ(t.per_streamline.size(), 1u);
  EXPECT_EQ(t.per_streamline[0].name, "w");
  EXPECT_EQ(t.per_streamline[0].values, (std::vector<float>{7, 8, 9}));
  EXPECT_EQ(h.declared_streamlines, 3);
}

TEST(TrkReader, appliesVoxelSizeHalfVoxelShiftAndVoxelOrderFlip) {
  // Identity vox_to_ras (RAS) but header voxel order LPS: x and y voxel
  // indices run the other way, i -> (dim - 1) - i, as nibabel's inv_ornt_aff.
  TempDir dir;
  TrkBytes b;
  b.put<int16_t>(6, 10);
  b.put<int16_t>(8, 20);
  b.put<int16_t>(10, 30);
  b.put<float>(12, 2.0f);
  b.put<float>(16, 4.0f);
  b.put<float>(20, 0.5f);
  std::memcpy(b.bytes().data() + 948, "LPS", 3);
  b.counts(0, 0, 1);
  b.streamline(1, {3.0f, 6.0f, 7.25f});
  Tractogram t;
  ASSERT_EQ(readAll(b.save(dir), &t), "");
  // voxel = voxmm / size - 0.5 = (1, 1, 14); flipped x, y: (8, 18, 14).
  EXPECT_EQ(t.positions, (std::vector<float>{8.0f, 18.0f, 14.0f}));
}

TEST(TrkReader, decodesNibabelStyleNamesAndNamesTheRest) {
  TempDir dir;
  TrkBytes b;
  b.counts(6, 3, 1);
  b.scalarName(0, std::string("rgb\0" "3", 5));
  b.scalarName(2, "fa");  // field 1 left empty: names nothing
  b.propertyName(0, std::string("pair\0" "2", 6));
  b.streamline(1, {0, 0, 0, 10, 11, 12, 13, 14, 15}, {1, 2, 3});
  Tractogram t;
  std::vector<std::string> warnings;
  ASSERT_EQ(readAll(b.save(dir), &t, &warnings), "");
  ASSERT_EQ(t.per_point.size(), 3u);
  EXPECT_EQ(t.per_point[0].name, "rgb");
  EXPECT_EQ(t.per_point[0].components, 3u);
  EXPECT_EQ(t.per_point[0].values, (std::vector<float>{10, 11, 12}));
  EXPECT_EQ(t.per_point[1].name, "fa");
  EXPECT_EQ(t.per_point[1].values, (std::vector<float>{13}));
  EXPECT_EQ(t.per_point[2].name, "scalar_4");  // the unnamed rest, as one array
  EXPECT_EQ(t.per_point[2].components, 2u);
  EXPECT_EQ(t.per_point[2].values, (std::vector<float>{14, 15}));
  ASSERT_EQ(t.per_streamline.size(), 2u);
  EXPECT_EQ(t.per_streamline[0].name, "pair");
  EXPECT_EQ(t.per_streamline[0].values, (std::vector<float>{1, 2}));
  EXPECT_EQ(t.per_streamline[1].name, "property_2");
  EXPECT_TRUE(warnings.empty()) << ::testing::PrintToString(warnings);
}

TEST(TrkReader, namesClaimingTooManyComponentsAreClippedWithAWarning) {
  TempDir dir;
  TrkBytes b;
  b.counts(2, 0, 1);
  b.scalarName(0, std::string("dir\0" "3", 5));
  b.scalarName(1, "fa");
  b.streamline(1, {0, 0, 0, 1, 2});
  Tractogram t;
  std::vector<std::string> warnings;
  ASSERT_EQ(readAll(b.save(dir), &t, &warnings), "");
  ASSERT_EQ(t.per_point.size(), 1u);
  EXPECT_EQ(t.per_point[0].components, 2u);
  EXPECT_TRUE(anyContains(warnings, "clipped"));
  EXPECT_TRUE(anyContains(warnings, "'fa'"));
}

TEST(TrkReader, rejectsShortFile) {
  TempDir dir;
  const std::string path = dir.file("short.trk");
  test::writeBytes(path, "TRACK");
  const std::string e = readAll(path);
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("1000"), std::string::npos) << e;
}

TEST(TrkReader, rejectsWrongMagic) {
  TempDir dir;
  TrkBytes b;
  std::memcpy(b.bytes().data(), "TRACX", 5);
  const std::string path = b.save(dir);
  const std::string e = readAll(path);
  EXPECT_EQ(e.rfind(path + ": byte 0:", 0), 0u) << e;
  EXPECT_NE(e.find("TRACK"), std::string::npos) << e;
}

TEST(TrkReader, rejectsHeaderSizeThatIs1000InNeitherByteOrder) {
  TempDir dir;
  TrkBytes b;
  b.put<int32_t>(996, 999);
  const std::string e = readAll(b.save(dir));
  EXPECT_NE(e.find("byte 996"), std::string::npos) << e;
  EXPECT_NE(e.find("hdr_size is 999"), std::string::npos) << e;
}

TEST(TrkReader, rejectsUnsupportedVersion) {
  TempDir dir;
  TrkBytes b;
  b.put<int32_t>(992, 7);
  const std::string e = readAll(b.save(dir));
  EXPECT_NE(e.find("version 7"), std::string::npos) << e;
}

TEST(TrkReader, rejectsSingularVoxToRas) {
  TempDir dir;
  TrkBytes b;
  b.put<float>(440 + 4 * 5, 0.0f);  // [1][1] = 0: the y axis has no direction
  const std::string e = readAll(b.save(dir));
  EXPECT_NE(e.find("singular"), std::string::npos) << e;
}

TEST(TrkReader, rejectsNegativePointCountWithOffset) {
  TempDir dir;
  TrkBytes b = smallTrk();
  const size_t second = 1000 + 4 + 2 * 16 + 4;
  b.put<int32_t>(second, -5);
  const std::string e = readAll(b.save(dir));
  EXPECT_NE(e.find("byte " + std::to_string(second) + ":"), std::string::npos) << e;
  EXPECT_NE(e.find("streamline 1"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
}

TEST(TrkReader, rejectsAbsurdPointCountWithOffset) {
  TempDir dir;
  for (int32_t m : {0x7fffffff, 100000000}) {
    TrkBytes b = smallTrk();
    b.put<int32_t>(1000, m);
    const std::string e = readAll(b.save(dir));
    EXPECT_NE(e.find("byte 1000:"), std::string::npos) << e;
    EXPECT_NE(e.find(std::to_string(m) + " points"), std::string::npos) << e;
  }
}

TEST(TrkReader, rejectsNaNWithStreamlineIndexAndOffset) {
  TempDir dir;
  TrkBytes b = smallTrk();
  const size_t at = 1000 + 4 + 2 * 16 + 4 + 4 + 4;  // streamline 1, point 0, y
  b.put<float>(at, std::nanf(""));
  const std::string e = readAll(b.save(dir));
  EXPECT_NE(e.find("byte " + std::to_string(at) + ":"), std::string::npos) << e;
  EXPECT_NE(e.find("streamline 1"), std::string::npos) << e;
  EXPECT_NE(e.find("NaN"), std::string::npos) << e;
}

TEST(TrkReader, warnsWhenCountIsWrongAndReadsWhatIsThere) {
  TempDir dir;
  for (int32_t declared : {2, 5}) {
    TrkBytes b = smallTrk();
    b.put<int32_t>(988, declared);
    Tractogram t;
    std::vector<std::string> warnings;
    ASSERT_EQ(readAll(b.save(dir), &t, &warnings), "");
    EXPECT_EQ(t.streamlineCount(), 3u);
    EXPECT_TRUE(anyContains(warnings, "n_count says " + std::to_string(declared))) << declared;
  }
}

TEST(TrkReader, readsToEndOfFileWhenCountIsZero) {
  TempDir dir;
  TrkBytes b = smallTrk();
  b.put<int32_t>(988, 0);
  Tractogram t;
  std::vector<std::string> warnings;
  TractogramHeader h;
  ASSERT_EQ(readAll(b.save(dir), &t, &warnings, &h), "");
  EXPECT_EQ(t.streamlineCount(), 3u);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(h.declared_streamlines, -1);
}

TEST(TrkReader, dropsTruncatedLastStreamlineWithAWarningNamingTheOffset) {
  TempDir dir;
  TrkBytes b = smallTrk();
  b.bytes().resize(b.bytes().size() - 6);
  Tractogram t;
  std::vector<std::string> warnings;
  ASSERT_EQ(readAll(b.save(dir), &t, &warnings), "");
  EXPECT_EQ(t.streamlineCount(), 2u);
  const size_t third = 1000 + (4 + 2 * 16 + 4) + (4 + 16 + 4);
  EXPECT_TRUE(anyContains(warnings, "byte " + std::to_string(third) + ": file is truncated"))
      << ::testing::PrintToString(warnings);
}

TEST(TrkReader, everyTruncatedPrefixThrowsOrReadsAConsistentPrefix) {
  TempDir dir;
  const std::string full = smallTrk().bytes();
  for (size_t n = 0; n < full.size(); ++n) {
    // A fresh file each time: truncating one file in place is slow on ext4.
    const std::string path = dir.file("prefix" + std::to_string(n) + ".trk");
    test::writeBytes(path, full.substr(0, n));
    Tractogram t;
    std::vector<std::string> warnings;
    const std::string e = readAll(path, &t, &warnings);
    if (!e.empty()) {
      EXPECT_LT(n, 1000u) << e;
      EXPECT_EQ(e.rfind(path, 0), 0u) << e;
      EXPECT_EQ(e.find('\n'), std::string::npos) << e;
      continue;
    }
    EXPECT_EQ(t.validate(), "") << n;
    EXPECT_LT(t.streamlineCount(), 3u) << n;
    EXPECT_FALSE(warnings.empty()) << n;  // a lost streamline is never silent
  }
}

TEST(TrkReader, scalarCountThatLiesGivesAnErrorOrAWarningNeverACrash) {
  TempDir dir;
  for (int16_t scalars : {0, 2, 3, 7, 200, 32767}) {
    TrkBytes b = smallTrk();
    b.put<int16_t>(36, scalars);
    Tractogram t;
    std::vector<std::string> warnings;
    const std::string e = readAll(b.save(dir), &t, &warnings);
    SCOPED_TRACE(scalars);
    if (e.empty()) {
      EXPECT_EQ(t.validate(), "");
      EXPECT_FALSE(warnings.empty());
    } else {
      EXPECT_NE(e.find("t.trk: byte "), std::string::npos) << e;
    }
  }
}

TEST(TrkReader, chunksHoldWholeStreamlinesAndBytesReadReachesTheEnd) {
  TempDir dir;
  const std::string path = smallTrk().save(dir);
  auto reader = openTrk(path);
  Tractogram chunk;
  std::vector<size_t> sizes;
  while (reader->read(chunk, 2)) {
    EXPECT_EQ(chunk.validate(), "");
    sizes.push_back(chunk.streamlineCount());
  }
  EXPECT_EQ(sizes, (std::vector<size_t>{1, 2}));  // 2 points; then 1 + 3 points
  EXPECT_EQ(reader->bytesRead(), std::filesystem::file_size(path));
  EXPECT_FALSE(reader->read(chunk));
}

// ---------------------------------------------------------------------------
// Writer.

TEST(TrkWriter, refusesToOverwriteUnlessAsked) {
  TempDir dir;
  const std::string path = dir.file("exists.trk");
  test::writeBytes(path, "keep me");
  TractogramHeader like;
  try {
    createTrkWriter(path, like, {});
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("exists"), std::string::npos);
  }
  EXPECT_EQ(test::readBytes(path), "keep me");
  WriterOptions force;
  force.overwrite = true;
  writeTractogram(path, test::smallTractogram(3), like, force);
  EXPECT_EQ(readAll(path), "");
}

TEST(TrkWriter, withoutAGridWarnsOnceAndWritesASyntheticGridCoveringTheData) {
  TempDir dir;
  const Tractogram t = test::smallTractogram(30, 3, true);
  TractogramHeader like;
  like.format = "tck";
  like.per_point = t.per_point;
  like.per_streamline = t.per_streamline;
  const std::string path = dir.file("synthetic.trk");
  std::vector<std::string> warnings;
  writeTractogram(path, t, like, {}, &warnings);
  ASSERT_EQ(warnings.size(), 1u) << ::testing::PrintToString(warnings);
  EXPECT_NE(warnings[0].find("synthetic"), std::string::npos);
  Tractogram back;
  TractogramHeader h;
  ASSERT_EQ(readAll(path, &back, nullptr, &h), "");
  EXPECT_EQ(h.space.voxel_order, "RAS");
  float max_coordinate[3] = {0, 0, 0};
  for (size_t i = 0; i < t.positions.size(); ++i) max_coordinate[i % 3] = std::max(max_coordinate[i % 3], t.positions[i]);
  for (int k = 0; k < 3; ++k) EXPECT_GE(h.space.dimensions[k], max_coordinate[k] + 0.5f) << k;
  ASSERT_EQ(back.offsets, t.offsets);
  for (size_t i = 0; i < t.positions.size(); ++i) ASSERT_NEAR(back.positions[i], t.positions[i], 1e-4) << i;
  EXPECT_EQ(back.per_point[0].values, t.per_point[0].values);
  EXPECT_EQ(back.per_streamline[0].values, t.per_streamline[0].values);
}

TEST(TrkWriter, takesTheGridFromTrkPropertiesWhenSpaceIsUnknown) {
  TempDir dir;
  TractogramHeader like;
  like.format = "tck";
  like.properties = {{"trk.dimensions", "20 30 40"},
                     {"trk.voxel_sizes", "2 2 2"},
                     {"trk.vox_to_ras", "2 0 0 -10 0 2 0 -20 0 0 2 -30 0 0 0 1"},
                     {"trk.voxel_order", "LAS"}};
  const std::string path = dir.file("grid.trk");
  std::vector<std::string> warnings;
  writeTractogram(path, test::smallTractogram(5), like, {}, &warnings);
  EXPECT_TRUE(warnings.empty()) << ::testing::PrintToString(warnings);
  TractogramHeader h;
  ASSERT_EQ(readAll(path, nullptr, nullptr, &h), "");
  EXPECT_EQ(h.space.voxel_order, "LAS");
  EXPECT_EQ(h.space.dimensions, (std::array<int32_t, 3>{20, 30, 40}));
  EXPECT_EQ(h.space.voxel_to_rasmm[3], -10.0f);
}

TEST(TrkWriter, dropsWhatDoesNotFitWithOneWarningEach) {
  TempDir dir;
  Tractogram t = test::smallTractogram(4);
  TractogramHeader like;
  like.space.known = true;
  for (int i = 0; i < 12; ++i) {
    DataArray a{"p" + std::to_string(i), 1, "float32", std::vector<float>(t.pointCount(), float(i))};
    t.per_point.push_back(a);
    like.per_point.push_back({a.name, 1, "float32", {}});
  }
  like.groups = {{"cst", {0, 1}}, {"af", {2}}};
  const std::string path = dir.file("many.trk");
  std::vector<std::string> warnings;
  writeTractogram(path, t, like, {}, &warnings);
  EXPECT_EQ(warnings.size(), 3u) << ::testing::PrintToString(warnings);
  EXPECT_TRUE(anyContains(warnings, "'p10'"));
  EXPECT_TRUE(anyContains(warnings, "'p11'"));
  EXPECT_TRUE(anyContains(warnings, "group"));
  Tractogram back;
  ASSERT_EQ(readAll(path, &back), "");
  ASSERT_EQ(back.per_point.size(), 10u);
  EXPECT_EQ(back.per_point[9].name, "p9");
  EXPECT_EQ(back.per_point[9].values, t.per_point[9].values);
}

TEST(TrkWriter, encodesComponentCountsInNamesAndPatchesTheCount) {
  TempDir dir;
  Tractogram t = test::smallTractogram(6);
  t.per_point.push_back({"rgb", 3, "float32", std::vector<float>(3 * t.pointCount(), 0.5f)});
  TractogramHeader like;
  like.space.known = true;
  like.per_point = {{"rgb", 3, "float32", {}}};
  const std::string path = dir.file("rgb.trk");
  writeTractogram(path, t, like);
  const std::string bytes = test::readBytes(path);
  EXPECT_EQ(bytes.substr(38, 6), std::string("rgb\0" "3\0", 6));
  int16_t n_scalars;
  int32_t n_count;
  std::memcpy(&n_scalars, bytes.data() + 36, 2);
  std::memcpy(&n_count, bytes.data() + 988, 4);
  EXPECT_EQ(n_scalars, 3);
  EXPECT_EQ(n_count, 6);
  Tractogram back;
  ASSERT_EQ(readAll(path, &back), "");
  ASSERT_EQ(back.per_point.size(), 1u);
  EXPECT_EQ(back.per_point[0].components, 3u);
}

TEST(TrkWriter, writesAnEmptyTractogramThatReadsBackEmpty) {
  TempDir dir;
  const std::string path = dir.file("empty.trk");
  TractogramHeader like;
  like.space.known = true;
  writeTractogram(path, Tractogram{}, like);
  EXPECT_EQ(std::filesystem::file_size(path), 1000u);
  Tractogram back;
  ASSERT_EQ(readAll(path, &back), "");
  EXPECT_EQ(back.streamlineCount(), 0u);
}

TEST(TrkWriter, leavesNoFileWithoutFinish) {
  TempDir dir;
  const std::string path = dir.file("unfinished.trk");
  {
    auto w = createTrkWriter(path, TractogramHeader{}, {});
    w->write(test::smallTractogram(3));
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

// ---------------------------------------------------------------------------
// The affine.

TEST(TrkAffine, axisCodesMatchNibabelsDocumentedExample) {
  // nibabel aff2axcodes docstring: [[0,1,0,10],[-1,0,0,20],[0,0,1,30]] -> ('B', 'R', 'U'),
  // i.e. posterior, right, superior.
  EXPECT_EQ(affineAxisCodes({0, 1, 0, 10, -1, 0, 0, 20, 0, 0, 1, 30, 0, 0, 0, 1}), "PRS");
  EXPECT_EQ(affineAxisCodes({-2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1}), "LAS");
  EXPECT_EQ(affineAxisCodes({1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}), "");  // singular
}

TEST(TrkAffine, rasToVoxmmToRasRoundTripsWithinFloatPrecision) {
  TrkGrid grid;
  grid.vox_to_ras = {0.0f, -1.1f, 0.3f, 80.0f, 1.9f, 0.2f, 0.0f, -110.0f, 0.1f, 0.0f, 2.4f, -70.0f, 0, 0, 0, 1};
  grid.voxel_sizes = {1.1f, 1.9f, 2.4f};
  grid.dimensions = {128, 128, 70};
  grid.voxel_order = "LPS";
  const Affine4 to_ras = trkVoxmmToRasmm(grid);
  const Affine4 to_voxmm = invertAffine(to_ras);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-120.f, 120.f);
  double worst = 0;
  for (int i = 0; i < 10000; ++i) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    float v[3], q[3];
    for (int k = 0; k < 3; ++k)
      v[k] = float(to_voxmm[4 * k] * p[0] + to_voxmm[4 * k + 1] * p[1] + to_voxmm[4 * k + 2] * p[2] + to_voxmm[4 * k + 3]);
    for (int k = 0; k < 3; ++k)
      q[k] = float(to_ras[4 * k] * v[0] + to_ras[4 * k + 1] * v[1] + to_ras[4 * k + 2] * v[2] + to_ras[4 * k + 3]);
    for (int k = 0; k < 3; ++k) worst = std::max(worst, std::fabs(q[k] - p[k]));
  }
  EXPECT_LE(worst, 3e-5);  // a few float ulps at 120 mm (ulp = 7.6e-6)
}


// Found by fuzz_trk: a file whose only streamline is truncated away reads as
// no streamlines under a header that still names its arrays (one of them
// with a newline in its name). Writing that back must give an empty file in
// every format, not an error ("chunk lacks the array"), whose message
// carried the raw name over two lines.
TEST(TrkWriter, emptyTractogramUnderAHeaderNamingArraysWritesInEveryFormat) {
  TempDir dir;
  TrkBytes b;
  b.scalarName(0, "a\nb");
  b.propertyName(0, "w");
  b.counts(1, 1, 1);
  b.put<int32_t>(1000, 3);  // 3 points of 4 floats and 1 property promised, 2 floats given
  b.put<float>(1004, 1.0f);
  b.put<float>(1008, 2.0f);
  Tractogram t;
  TractogramHeader h;
  std::vector<std::string> warnings;
  ASSERT_EQ(readAll(b.save(dir), &t, &warnings, &h), "");
  ASSERT_EQ(t.streamlineCount(), 0u);
  ASSERT_EQ(h.per_point.size(), 1u);
  ASSERT_EQ(h.per_streamline.size(), 1u);
  EXPECT_EQ(h.per_point[0].name, "a\nb");
  WriterOptions options;
  options.overwrite = true;
  for (const char* name : {"out.trk", "out.tck"}) {
    const std::string out = dir.file(name);
    std::vector<std::string> dropped;
    ASSERT_NO_THROW(writeTractogram(out, t, h, options, &dropped)) << name;
    for (const std::string& w : dropped) EXPECT_EQ(w.find('\n'), std::string::npos) << w;
    Tractogram chunk;
    EXPECT_FALSE(openTractogram(out)->read(chunk)) << name;
  }
  // TRX stores each array as a file named after it: a newline cannot be one.
  // The refusal is one line that names the output.
  try {
    writeTractogram(dir.file("out.trx"), t, h, options);
    ADD_FAILURE() << "a TRX member named 'a\\nb' was written";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find("out.trx"), std::string::npos) << message;
    EXPECT_NE(message.find("'a b'"), std::string::npos) << message;
  }
  // Under valid names the same empty tractogram is an empty TRX.
  h.per_point[0].name = "ab";
  ASSERT_NO_THROW(writeTractogram(dir.file("valid.trx"), t, h, options));
  Tractogram chunk;
  EXPECT_FALSE(openTractogram(dir.file("valid.trx"))->read(chunk));
}

}  // namespace
}  // namespace fibscope
