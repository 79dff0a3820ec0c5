// The viewer's selection and the export of selected fibers: the .tck holds
// exactly the points `fibscope decompress` (openFbl) gives for those fibers,
// bit for bit; nibabel reads the same values (independent reader).
#include "render/fiber_selection.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "codec/compressor.h"
#include "codec/fbl_reader.h"
#include "core/error.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "test_support.h"

namespace fibscope {
namespace {

TEST(FiberSelection, selectToggleAndClearKeepSelectionOrderWithoutDuplicates) {
  FiberSelection s;
  EXPECT_TRUE(s.empty());
  s.select(7);
  EXPECT_EQ(s.fibers(), (std::vector<uint32_t>{7}));
  s.toggle(3);
  s.toggle(11);
  s.add(3);  // already there: no duplicate
  EXPECT_EQ(s.fibers(), (std::vector<uint32_t>{7, 3, 11}));
  EXPECT_TRUE(s.contains(11));
  s.toggle(3);  // ctrl-click on a selected fiber removes it
  EXPECT_EQ(s.fibers(), (std::vector<uint32_t>{7, 11}));
  EXPECT_FALSE(s.contains(3));
  s.select(5);  // a plain click replaces the selection
  EXPECT_EQ(s.fibers(), (std::vector<uint32_t>{5}));
  const uint64_t revision = s.revision();
  s.remove(99);  // not selected: nothing changes
  EXPECT_EQ(s.revision(), revision);
  s.clear();
  EXPECT_TRUE(s.empty());
  EXPECT_NE(s.revision(), revision);
}

TEST(FiberSelection, bitWordsSetBitFiberMod32OfWordFiberDiv32) {
  FiberSelection s;
  for (uint32_t f : {0u, 31u, 32u, 65u, 1000u}) s.toggle(f);
  const std::vector<uint32_t> words = s.bitWords(100);  // 1000 is past the count: left out
  ASSERT_EQ(words.size(), 4u);                          // ceil(100 / 32)
  EXPECT_EQ(words[0], 0x80000001u);
  EXPECT_EQ(words[1], 0x00000001u);
  EXPECT_EQ(words[2], 0x00000002u);
  EXPECT_EQ(words[3], 0u);
  EXPECT_EQ(s.bitWords(0).size(), 0u);
  EXPECT_EQ(s.bitWords(32).size(), 1u);
  EXPECT_EQ(s.bitWords(33).size(), 2u);
}

class FiberExport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    CompressOptions options;
    options.terminal_progress = false;
    options.threads = 1;
    compressTractogram(
        [] {
          PhantomOptions p;
          p.streamlines = 60;
          p.step_mm = 0.5;
          p.seed = 17;
          p.threads = 1;
          return openPhantom(p);
        },
        fbl(), options);
    whole_ = new Tractogram(readAllStreamlines(*openFbl(fbl())));
  }
  static void TearDownTestSuite() {
    delete whole_;
    delete dir_;
  }
  static std::string fbl() { return dir_->file("phantom.fbl"); }
  static test::TempDir* dir_;
  static Tractogram* whole_;
};
test::TempDir* FiberExport::dir_ = nullptr;
Tractogram* FiberExport::whole_ = nullptr;

void expectSameFibers(const Tractogram& exported, const Tractogram& whole, const std::vector<uint32_t>& ids) {
  ASSERT_EQ(exported.streamlineCount(), ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    ASSERT_EQ(exported.pointsIn(i), whole.pointsIn(ids[i])) << "fiber " << ids[i];
    const size_t n = 3 * exported.pointsIn(i);
    EXPECT_EQ(std::memcmp(exported.point(exported.offsets[i]), whole.point(whole.offsets[ids[i]]), n * sizeof(float)),
              0)
        << "fiber " << ids[i] << ": points differ";
  }
}

TEST_F(FiberExport, exportedFibersEqualTheSameFibersOfTheDecompressedFileBitForBit) {
  const FblFile file = FblFile::open(fbl());
  ASSERT_EQ(file.header().fiber_count, 60u);
  const std::vector<uint32_t> ids = {42, 0, 17, 59, 3};
  const std::string out = dir_->file("selection.tck");
  exportFibers(file, ids, out);
  expectSameFibers(readAllStreamlines(*openTractogram(out)), *whole_, ids);
  // Exporting again overwrites (the viewer's export button, pressed twice).
  exportFibers(file, std::vector<uint32_t>{8}, out);
  expectSameFibers(readAllStreamlines(*openTractogram(out)), *whole_, {8});
  EXPECT_THROW(exportFibers(file, std::vector<uint32_t>{8}, out, /*overwrite=*/false), Error);
}

TEST_F(FiberExport, nibabelReadsTheExportedPoints) {
  const std::string python = test::pythonWithNibabel();
  if (python.empty()) GTEST_SKIP() << "no /usr/bin/python3 with nibabel";
  const FblFile file = FblFile::open(fbl());
  const std::vector<uint32_t> ids = {1, 30, 2};
  const std::string out = dir_->file("nibabel.tck");
  exportFibers(file, ids, out);
  const auto r = test::runCommand(python + " " + test::toolPath("tck_reference.py") + " read " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const size_t begin = r.output.find('{');
  ASSERT_NE(begin, std::string::npos) << r.output;
  const nlohmann::json j = nlohmann::json::parse(r.output.substr(begin, r.output.find('\n', begin) - begin));
  Tractogram read;
  const auto lengths = j["lengths"].get<std::vector<size_t>>();
  const auto points = j["points"].get<std::vector<double>>();
  size_t at = 0;
  for (size_t n : lengths) {
    std::vector<float> xyz(points.begin() + at, points.begin() + at + 3 * n);  // float32 values, exact
    read.addStreamline(xyz.data(), n);
    at += 3 * n;
  }
  EXPECT_EQ(j["count"].get<size_t>(), ids.size());
  expectSameFibers(read, *whole_, ids);
}

TEST_F(FiberExport, badIdsAndEmptySelectionsAreOneLineErrorsAndWriteNothing) {
  const FblFile file = FblFile::open(fbl());
  const std::string out = dir_->file("bad.tck");
  try {
    exportFibers(file, std::vector<uint32_t>{2, 60}, out);
    FAIL() << "an id past the fiber count must throw";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(fbl()), std::string::npos) << message;
    EXPECT_NE(message.find("60"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  try {
    exportFibers(file, {}, out);
    FAIL() << "an empty selection must throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(out), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  // A directory that does not exist: the writer's error, naming the path.
  EXPECT_THROW(exportFibers(file, std::vector<uint32_t>{1}, dir_->file("missing/dir.tck")), Error);
}

TEST_F(FiberExport, fiberLengthComesFromTheLengthSection) {
  const FblFile file = FblFile::open(fbl());
  for (uint32_t f : {0u, 25u, 59u}) {
    const std::optional<float> length = fiberLengthMm(file, f);
    ASSERT_TRUE(length.has_value());
    // The decoded fiber is within micrometres of the compressed one.
    const float decoded = polylineLength(whole_->point(whole_->offsets[f]), whole_->pointsIn(f));
    EXPECT_NEAR(*length, decoded, 1e-3 * decoded + 0.01) << f;
  }
  EXPECT_THROW(fiberLengthMm(file, 60), Error);
}

}  // namespace
}  // namespace fibscope
