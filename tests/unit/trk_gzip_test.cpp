// gzip-compressed TrackVis files (DSI Studio's .trk.gz): read through the
// same .trk reader as plain files, told by the gzip magic. The reference is
// the plain file: the same bytes uncompressed must read to the same
// tractogram, header and data, whatever the chunk size; damaged streams
// are one-line errors naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "read_whole.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::readWhole;
using Read = test::WholeRead;
std::string errorOf(const std::string& path) { return test::readError(path); }

// Many short streamlines with a per-point and a per-streamline array, and
// one of 300 k points (3.6 MB of records: several of the window's 1 MiB
// steps in one streamline).
Tractogram mixed() {
  Tractogram t = test::smallTractogram(400, 5, /*with_data=*/true);
  std::vector<float> xyz;
  for (int i = 0; i < 300000; ++i) {
    xyz.push_back(float(i % 1000) * 0.1f);
    xyz.push_back(float(i / 1000) * 0.2f);
    xyz.push_back(std::sin(float(i) * 1e-3f));
  }
  Tractogram big;
  big.per_point = t.per_point;
  big.per_streamline = t.per_streamline;
  for (auto& a : big.per_point) a.values.assign(size_t(300000) * a.components, 0.5f);
  for (auto& a : big.per_streamline) a.values.assign(a.components, 2.0f);
  big.addStreamline(xyz.data(), 300000);
  t.append(big);
  return t;
}

class TrkGzip : public ::testing::Test {
 protected:
  void SetUp() override {
    plain_ = dir_.file("t.trk");
    WriterOptions options;
    writeTractogram(plain_, mixed(), TractogramHeader{}, options);
    gz_ = dir_.file("t.trk.gz");
    test::writeBytes(gz_, test::gzipBytes(test::readBytes(plain_)));
  }
  test::TempDir dir_;
  std::string plain_, gz_;
};

TEST_F(TrkGzip, readsExactlyAsThePlainFileAtEveryChunkSize) {
  const Read want = readWhole(plain_, 1 << 16);
  ASSERT_GT(want.all.streamlineCount(), 400u);
  ASSERT_FALSE(want.all.per_point.empty());
  ASSERT_FALSE(want.all.per_streamline.empty());
  for (size_t max_points : {size_t(1), size_t(700), size_t(1) << 18}) {
    SCOPED_TRACE(max_points);
    const Read got = readWhole(gz_, max_points);
    EXPECT_EQ(got.all.offsets, want.all.offsets);
    EXPECT_EQ(got.all.positions, want.all.positions);
    ASSERT_EQ(got.all.per_point.size(), want.all.per_point.size());
    for (size_t i = 0; i < want.all.per_point.size(); ++i) {
      EXPECT_EQ(got.all.per_point[i].name, want.all.per_point[i].name);
      EXPECT_EQ(got.all.per_point[i].values, want.all.per_point[i].values);
    }
    ASSERT_EQ(got.all.per_streamline.size(), want.all.per_streamline.size());
    for (size_t i = 0; i < want.all.per_streamline.size(); ++i)
      EXPECT_EQ(got.all.per_streamline[i].values, want.all.per_streamline[i].values);
    EXPECT_EQ(got.header.properties, want.header.properties);
    EXPECT_EQ(got.header.space.voxel_to_rasmm, want.header.space.voxel_to_rasmm);
    EXPECT_EQ(got.header.declared_streamlines, want.header.declared_streamlines);
    EXPECT_EQ(got.warnings, want.warnings);
    // Progress counts the compressed file, never backwards, to its end.
    const uint64_t size = std::filesystem::file_size(gz_);
    EXPECT_EQ(got.header.file_bytes, size);
    for (size_t i = 1; i < got.progress.size(); ++i) EXPECT_LE(got.progress[i - 1], got.progress[i]);
    EXPECT_LE(got.progress.front(), size);
    EXPECT_EQ(got.progress.back(), size);
  }
}

// The command line takes it as any input: `convert` of the .trk.gz writes
// the bytes `convert` of the plain file writes.
TEST_F(TrkGzip, convertWritesWhatThePlainFileGives) {
  const std::string from_plain = dir_.file("plain.tck"), from_gz = dir_.file("gz.tck");
  const auto a = test::runFibscope("convert " + plain_ + " " + from_plain);
  const auto b = test::runFibscope("convert " + gz_ + " " + from_gz);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_EQ(test::readBytes(from_gz), test::readBytes(from_plain));
  test::writeBytes(dir_.file("t.tck.gz"), test::gzipBytes("mrtrix tracks\nEND\n"));
  const auto bad = test::runFibscope("info " + dir_.file("t.tck.gz"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("decompress it first"), std::string::npos) << bad.output;
}

TEST_F(TrkGzip, theMagicDecidesNotTheName) {
  const Read want = readWhole(plain_, 1 << 16);
  const std::string gz_named_trk = dir_.file("gz.trk"), plain_named_gz = dir_.file("plain.trk.gz");
  std::filesystem::copy_file(gz_, gz_named_trk);
  std::filesystem::copy_file(plain_, plain_named_gz);
  EXPECT_EQ(readWhole(gz_named_trk, 1 << 16).all.positions, want.all.positions);
  EXPECT_EQ(readWhole(plain_named_gz, 1 << 16).all.positions, want.all.positions);
}

TEST_F(TrkGzip, damagedStreamsAreOneLineErrorsNamingTheFile) {
  const std::string bytes = test::readBytes(gz_);
  const std::string cut = dir_.file("cut.trk.gz"), flipped = dir_.file("flipped.trk.gz");
  test::writeBytes(cut, bytes.substr(0, bytes.size() / 2));
  std::string damaged = bytes;
  damaged[damaged.size() / 2] ^= 0x5a;
  test::writeBytes(flipped, damaged);
  for (const std::string& path : {cut, flipped}) {
    const std::string e = errorOf(path);
    EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  EXPECT_NE(errorOf(cut).find("cut short"), std::string::npos);
}

// A count no tracker writes (2^30 points: 12 GB of records) is refused
// before the window tries to hold it, although the stream could be long.
TEST(TrkGzipCounts, anImplausiblePointCountIsAnErrorBeforeAnyAllocation) {
  test::TempDir dir;
  const std::string plain = dir.file("one.trk");
  Tractogram t;
  const float xyz[6] = {1, 2, 3, 4, 5, 6};
  t.addStreamline(xyz, 2);
  writeTractogram(plain, t, TractogramHeader{}, WriterOptions{});
  std::string bytes = test::readBytes(plain);
  const int32_t huge = int32_t(1) << 30;
  std::memcpy(bytes.data() + 1000, &huge, 4);
  const std::string gz = dir.file("lying.trk.gz");
  test::writeBytes(gz, test::gzipBytes(bytes));
  const std::string e = errorOf(gz);
  EXPECT_EQ(e.rfind(gz + ": byte 1000: ", 0), 0u) << e;
  EXPECT_NE(e.find("implausible"), std::string::npos) << e;
}

TEST(TrkGzipCounts, otherCompressedFormatsAreNamedNotMisread) {
  test::TempDir dir;
  for (const char* name : {"t.tck.gz", "t.vtk.gz", "t.trx.gz"}) {
    const std::string path = dir.file(name);
    test::writeBytes(path, test::gzipBytes("mrtrix tracks\nEND\n"));
    const std::string e = errorOf(path);
    EXPECT_EQ(e.rfind(path + ": ", 0), 0u) << e;
    EXPECT_NE(e.find("decompress it first"), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace fibscope
