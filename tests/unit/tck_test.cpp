// .tck / .tsf reader and writer. Expected bytes are built here from the
// format description (MRtrix3 docs), independently of io/tck_format, and
// nibabel (tests/tools/tck_reference.py) is the outside reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/reader.h"
#include "io/tsf.h"
#include "io/writer.h"
#include "test_support.h"

namespace fibscope {
namespace {

static_assert(std::endian::native == std::endian::little, "the byte builders below assume a little-endian host");

using Samples = std::vector<std::vector<float>>;  // per streamline: x,y,z,x,y,z... (or one value per point)

const float kNaN = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

void putSample(std::string& out, double v, const std::string& datatype) {
  char bytes[8];
  size_t n = 4;
  if (datatype.rfind("Float64", 0) == 0) {
    std::memcpy(bytes, &v, 8);
    n = 8;
  } else {
    const float f = static_cast<float>(v);
    std::memcpy(bytes, &f, 4);
  }
  if (datatype.size() > 2 && datatype.substr(datatype.size() - 2) == "BE") std::reverse(bytes, bytes + n);
  out.append(bytes, n);
}

// A track file as the format description lays it out.
struct TrackSpec {
  Samples streamlines;
  std::string magic = "mrtrix tracks";
  size_t per_point = 3;  // samples per point (1 for .tsf)
  std::string datatype = "Float32LE";
  std::string extra_header;    // "key: value\n" lines before datatype
  std::string count = "auto";  // "auto": the true count; "": no count line
  bool terminator = true;
  size_t padding = 0;  // zero bytes between END and the data, as MRtrix leaves
};

std::string buildTrackFile(const TrackSpec& spec, size_t* data_offset = nullptr) {
  std::string head = spec.magic + "\n" + spec.extra_header + "datatype: " + spec.datatype + "\n";
  if (spec.count == "auto")
    head += "count: " + std::to_string(spec.streamlines.size()) + "\n";
  else if (!spec.count.empty())
    head += "count: " + spec.count + "\n";
  size_t offset = 0;
  for (size_t digits = 1;; ++digits) {
    offset = head.size() + std::strlen("file: . ") + digits + std::strlen("\nEND\n") + spec.padding;
    if (std::to_string(offset).size() == digits) break;
  }
  std::string out = head + "file: . " + std::to_string(offset) + "\nEND\n" + std::string(spec.padding, '\0');
  if (data_offset) *data_offset = offset;
  for (const auto& s : spec.streamlines) {
    for (float v : s) putSample(out, v, spec.datatype);
    for (size_t k = 0; k < spec.per_point; ++k) putSample(out, kNaN, spec.datatype);
  }
  if (spec.terminator)
    for (size_t k = 0; k < spec.per_point; ++k) putSample(out, kInf, spec.datatype);
  return out;
}

TrackSpec tsfSpec(const Samples& values) {
  TrackSpec spec;
  spec.magic = "mrtrix track scalars";
  spec.per_point = 1;
  spec.streamlines = values;
  return spec;
}

Tractogram fromSamples(const Samples& streamlines) {
  Tractogram t;
  for (const auto& s : streamlines) t.addStreamline(s.data(), s.size() / 3);
  return t;
}

struct ReadResult {
  Tractogram tractogram;
  TractogramHeader header;
  std::vector<std::string> warnings;
};

// Reads everything through small chunks, checking the chunk contract.
ReadResult readAll(const std::string& path, const std::vector<std::string>& tsf = {}, size_t max_points = 7) {
  auto reader = openTck(path, tsf);
  ReadResult r;
  r.tractogram.per_point = reader->header().per_point;
  Tractogram chunk;
  while (reader->read(chunk, max_points)) {
    EXPECT_EQ(chunk.validate(), "");
    EXPECT_GT(chunk.streamlineCount(), 0u);
    // Whole streamlines only: the chunk goes past max_points by at most its last one.
    if (chunk.streamlineCount() > 1) {
      EXPECT_LT(chunk.offsets[chunk.streamlineCount() - 1], max_points);
    }
    r.tractogram.append(chunk);
  }
  EXPECT_FALSE(reader->read(chunk, max_points));
  EXPECT_EQ(reader->bytesRead(), reader->header().file_bytes);
  r.header = reader->header();
  r.warnings = reader->warnings();
  return r;
}

void expectSameStreamlines(const Tractogram& actual, const Tractogram& expected) {
  ASSERT_EQ(actual.streamlineCount(), expected.streamlineCount());
  EXPECT_EQ(actual.offsets, expected.offsets);
  ASSERT_EQ(actual.positions.size(), expected.positions.size());
  // Bit-exact: formats store float32 and nothing is converted.
  EXPECT_EQ(std::memcmp(actual.positions.data(), expected.positions.data(), 4 * actual.positions.size()), 0);
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "<no error>";
}

// One line, naming the file first, containing `needle`.
void expectError(const std::string& message, const std::string& path, const std::string& needle) {
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find(needle), std::string::npos) << message << "\n  expected to contain: " << needle;
}

size_t fileCount(const test::TempDir& dir) {
  return static_cast<size_t>(
      std::distance(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator()));
}

const Samples kThree = {{1, 2, 3, 4, 5, 6}, {7.5f, -8, 9.25f}, {10, 11, 12, 13, 14, 15, 16, 17, 18}};

// --- reader --------------------------------------------------------------

TEST(TckReader, readsHandBuiltFileExactly) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  spec.extra_header = "command_history: tckgen a b\nroi: seed a.nii\nroi: mask b.nii\n";
  test::writeBytes(dir.file("a.tck"), buildTrackFile(spec));
  const ReadResult r = readAll(dir.file("a.tck"));
  expectSameStreamlines(r.tractogram, fromSamples(kThree));
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(r.header.format, "tck");
  EXPECT_EQ(r.header.declared_streamlines, 3);
  // Every key in file order, repeats kept apart.
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"command_history", "tckgen a b"}, {"roi", "seed a.nii"}, {"roi", "mask b.nii"},
      {"datatype", "Float32LE"},         {"count", "3"},        {"file", r.header.property("file")}};
  EXPECT_EQ(r.header.properties, expected);
}

TEST(TckReader, readsEveryDatatype) {
  test::TempDir dir;
  for (const std::string dt : {"Float32LE", "Float32BE", "Float64LE", "Float64BE"}) {
    TrackSpec spec;
    spec.streamlines = kThree;
    spec.datatype = dt;
    test::writeBytes(dir.file(dt + ".tck"), buildTrackFile(spec));
    const ReadResult r = readAll(dir.file(dt + ".tck"));
    expectSameStreamlines(r.tractogram, fromSamples(kThree));
    EXPECT_TRUE(r.warnings.empty()) << dt;
  }
}

TEST(TckReader, keepsZeroLengthStreamlines) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = {{1, 2, 3}, {}, {}, {4, 5, 6, 7, 8, 9}};
  test::writeBytes(dir.file("z.tck"), buildTrackFile(spec));
  const ReadResult r = readAll(dir.file("z.tck"));
  ASSERT_EQ(r.tractogram.streamlineCount(), 4u);
  EXPECT_EQ(r.tractogram.offsets, (std::vector<uint64_t>{0, 1, 1, 1, 3}));
  EXPECT_TRUE(r.warnings.empty());
}

TEST(TckReader, acceptsPaddingBetweenEndAndData) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  spec.padding = 41;  // MRtrix reserves room to rewrite the counts
  test::writeBytes(dir.file("p.tck"), buildTrackFile(spec));
  const ReadResult r = readAll(dir.file("p.tck"));
  expectSameStreamlines(r.tractogram, fromSamples(kThree));
  EXPECT_TRUE(r.warnings.empty());
}

TEST(TckReader, reportsWrongCount) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  spec.count = "5";
  const std::string path = dir.file("c.tck");
  test::writeBytes(path, buildTrackFile(spec));
  const ReadResult r = readAll(path);
  EXPECT_EQ(r.tractogram.streamlineCount(), 3u);
  EXPECT_EQ(r.warnings, std::vector<std::string>{path + ": header says count 5 but the file holds 3 streamlines"});
}

TEST(TckReader, reportsMissingCount) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  spec.count = "";
  const std::string path = dir.file("c.tck");
  test::writeBytes(path, buildTrackFile(spec));
  const ReadResult r = readAll(path);
  EXPECT_EQ(r.tractogram.streamlineCount(), 3u);
  EXPECT_EQ(r.header.declared_streamlines, -1);
  EXPECT_EQ(r.warnings, std::vector<std::string>{path + ": header has no count; the file holds 3 streamlines"});
}

TEST(TckReader, doesNotDeclareAnImpossibleCount) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  spec.count = "1000000000000";
  const std::string path = dir.file("c.tck");
  test::writeBytes(path, buildTrackFile(spec));
  const ReadResult r = readAll(path);
  EXPECT_EQ(r.header.declared_streamlines, -1);
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_NE(r.warnings[0].find("header count 1000000000000 is impossible"), std::string::npos) << r.warnings[0];
  EXPECT_EQ(r.warnings[1], path + ": header says count 1000000000000 but the file holds 3 streamlines");
}

TEST(TckReader, readsTruncatedFileUpToTheLastWholeStreamline) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  spec.terminator = false;
  std::string bytes = buildTrackFile(spec);
  // Cut inside the x of the third point of the last streamline: two whole points remain.
  bytes.resize(bytes.size() - 12 /*separator*/ - 12 /*point 3*/ + 2);
  const std::string path = dir.file("t.tck");
  test::writeBytes(path, bytes);
  const ReadResult r = readAll(path);
  expectSameStreamlines(r.tractogram, fromSamples({kThree[0], kThree[1]}));
  EXPECT_EQ(r.warnings,
            (std::vector<std::string>{path + ": no terminator: file truncated at byte " + std::to_string(bytes.size()) +
                                          ", last partial streamline of 2 points dropped",
                                      path + ": header says count 3 but the file holds 2 streamlines"}));
}

TEST(TckReader, readsFileEndingAfterASeparatorWithAWarning) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  spec.terminator = false;
  const std::string bytes = buildTrackFile(spec);
  const std::string path = dir.file("t.tck");
  test::writeBytes(path, bytes);
  const ReadResult r = readAll(path);
  expectSameStreamlines(r.tractogram, fromSamples(kThree));
  EXPECT_EQ(r.warnings, std::vector<std::string>{path + ": no terminator: file truncated at byte " +
                                                 std::to_string(bytes.size()) + " after 3 complete streamlines"});
}

TEST(TckReader, everyTruncatedPrefixReadsAPrefixOrThrows) {
  test::TempDir dir;
  for (const std::string dt : {"Float32LE", "Float64BE"}) {
    TrackSpec spec;
    spec.streamlines = {{1, 2, 3, 4, 5, 6}, {}, {7, 8, 9}, {10, 11, 12, 13, 14, 15, 16, 17, 18}};
    spec.datatype = dt;
    spec.padding = 3;
    spec.extra_header = "roi: seed x.nii\n";
    size_t data_offset = 0;
    const std::string full = buildTrackFile(spec, &data_offset);
    const Tractogram expected = fromSamples(spec.streamlines);
    for (size_t n = 0; n <= full.size(); ++n) {
      SCOPED_TRACE(dt + " prefix of " + std::to_string(n) + " bytes");
      // A fresh name each time: rewriting one file in place makes ext4 flush it on close (slow).
      const std::string path = dir.file(dt + "-" + std::to_string(n) + ".tck");
      test::writeBytes(path, full.substr(0, n));
      try {
        const ReadResult r = readAll(path);
        const Tractogram& t = r.tractogram;
        ASSERT_LE(t.streamlineCount(), expected.streamlineCount());
        for (size_t i = 0; i < t.streamlineCount(); ++i) {
          ASSERT_EQ(t.pointsIn(i), expected.pointsIn(i));
          EXPECT_EQ(0, std::memcmp(t.point(t.offsets[i]), expected.point(expected.offsets[i]), 12 * t.pointsIn(i)));
        }
        if (n < full.size()) {
          EXPECT_FALSE(r.warnings.empty());
        } else {
          EXPECT_EQ(t.streamlineCount(), 4u);
          EXPECT_TRUE(r.warnings.empty());
        }
      } catch (const Error& e) {
        expectError(e.what(), path, "");
        // Once the whole header is there, a cut file reads with a warning.
        EXPECT_LT(n, data_offset) << e.what();
      }
      std::filesystem::remove(path);
    }
  }
}

TEST(TckReader, rejectsWrongMagic) {
  test::TempDir dir;
  TrackSpec spec;
  spec.magic = "mrtrix trucks";
  const std::string path = dir.file("m.tck");
  test::writeBytes(path, buildTrackFile(spec));
  expectError(errorOf([&] { openTck(path); }), path, "first line is 'mrtrix trucks', expected 'mrtrix tracks'");
  // A .tsf handed over as a tractogram is named as such.
  test::writeBytes(path, buildTrackFile(tsfSpec({{1, 2}})));
  expectError(errorOf([&] { openTck(path); }), path, "is a track scalar file (.tsf)");
  test::writeBytes(path, std::string("\x89PNG\r\n\x1a\n", 8));
  expectError(errorOf([&] { openTck(path); }), path, "first line is '?PNG', expected");
  test::writeBytes(path, "");
  expectError(errorOf([&] { openTck(path); }), path, "empty file");
}

TEST(TckReader, rejectsMissingDatatype) {
  test::TempDir dir;
  const std::string path = dir.file("d.tck");
  test::writeBytes(path, "mrtrix tracks\ncount: 0\nfile: . 43\nEND\n");
  expectError(errorOf([&] { openTck(path); }), path, "no datatype specified");
}

TEST(TckReader, rejectsUnsupportedDatatype) {
  test::TempDir dir;
  TrackSpec spec;
  spec.datatype = "Int16LE";
  const std::string path = dir.file("d.tck");
  test::writeBytes(path, buildTrackFile(spec));
  expectError(errorOf([&] { openTck(path); }), path, "datatype 'Int16LE' is not supported");
}

TEST(TckReader, rejectsMissingEnd) {
  test::TempDir dir;
  const std::string path = dir.file("e.tck");
  test::writeBytes(path, "mrtrix tracks\ndatatype: Float32LE\nfile: . 40\n");
  expectError(errorOf([&] { openTck(path); }), path, "header has no END line (the file ends at byte 45");
}

TEST(TckReader, rejectsBadDataOffsets) {
  test::TempDir dir;
  const std::string path = dir.file("o.tck");
  const std::string head = "mrtrix tracks\ndatatype: Float32LE\ncount: 0\n";
  const std::string inf(12, '\0');
  // Inside the header (which ends after "END\n").
  test::writeBytes(path, head + "file: . 20\nEND\n" + inf);
  expectError(errorOf([&] { openTck(path); }), path, "data offset 20 lies inside the header, which ends at byte 58");
  // Past the end of the file.
  test::writeBytes(path, head + "file: . 71\nEND\n" + inf);
  expectError(errorOf([&] { openTck(path); }), path, "data offset 71 is beyond the end of the file (70 bytes)");
  // Absurd: more digits than any offset.
  test::writeBytes(path, head + "file: . 99999999999999999999999999\nEND\n" + inf);
  expectError(errorOf([&] { openTck(path); }), path, "data offset 99999999999999999999999999 is beyond the end");
  test::writeBytes(path, head + "file: . -4\nEND\n" + inf);
  expectError(errorOf([&] { openTck(path); }), path, "is not '. OFFSET'");
  test::writeBytes(path, head + "file: data.bin 0\nEND\n" + inf);
  expectError(errorOf([&] { openTck(path); }), path, "names a separate data file");
  test::writeBytes(path, head + "END\n" + inf);
  expectError(errorOf([&] { openTck(path); }), path, "no 'file: . OFFSET' line");
}

TEST(TckReader, rejectsPartialNanTriplet) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = {{1, 2, 3, 4, kNaN, 6}, {7, 8, 9}};
  size_t offset = 0;
  const std::string path = dir.file("n.tck");
  test::writeBytes(path, buildTrackFile(spec, &offset));
  expectError(errorOf([&] { readAll(path); }), path,
              "byte " + std::to_string(offset + 12) + ": streamline 0 point 1 is (a number, NaN, a number)");
  spec.streamlines = {{1, 2, 3}, {kNaN, kNaN, 4}};
  test::writeBytes(path, buildTrackFile(spec, &offset));
  expectError(errorOf([&] { readAll(path); }), path,
              "byte " + std::to_string(offset + 24) + ": streamline 1 point 0 is (NaN, NaN, a number)");
}

TEST(TckReader, rejectsInfInsideAStreamline) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = {{1, 2, 3, 4, 5, -kInf}};
  spec.datatype = "Float64BE";
  size_t offset = 0;
  const std::string path = dir.file("i.tck");
  test::writeBytes(path, buildTrackFile(spec, &offset));
  expectError(errorOf([&] { readAll(path); }), path,
              "byte " + std::to_string(offset + 24) + ": streamline 0 point 1 is (a number, a number, Inf)");
}

TEST(TckReader, rejectsFloat64BeyondFloatRange) {
  test::TempDir dir;
  std::string bytes = "mrtrix tracks\ndatatype: Float64LE\nfile: . 49\nEND\n";
  ASSERT_EQ(bytes.size(), 49u);
  for (double v : {1.0, 1e300, 2.0, double(kNaN), double(kNaN), double(kNaN), double(kInf), double(kInf), double(kInf)})
    putSample(bytes, v, "Float64LE");
  const std::string path = dir.file("r.tck");
  test::writeBytes(path, bytes);
  expectError(errorOf([&] { readAll(path); }), path, "byte 57: sample");
}

TEST(TckReader, dropsStreamlineThatTheTerminatorCutsShort) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = {{1, 2, 3}};
  spec.terminator = false;
  std::string bytes = buildTrackFile(spec);
  for (float v : {4.f, 5.f, 6.f, kInf, kInf, kInf}) putSample(bytes, v, "Float32LE");
  const std::string path = dir.file("s.tck");
  test::writeBytes(path, bytes);
  const ReadResult r = readAll(path);
  EXPECT_EQ(r.tractogram.streamlineCount(), 1u);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0], path + ": streamline 1 (1 points) has no NaN separator before the Inf terminator at byte " +
                               std::to_string(bytes.size() - 12) + "; dropped");
}

TEST(TckReader, warnsAboutBytesAfterTheTerminator) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  const std::string path = dir.file("x.tck");
  const std::string bytes = buildTrackFile(spec);
  test::writeBytes(path, bytes + "junk!");
  const ReadResult r = readAll(path);
  expectSameStreamlines(r.tractogram, fromSamples(kThree));
  EXPECT_EQ(r.warnings, std::vector<std::string>{path + ": 5 bytes after the Inf terminator at byte " +
                                                 std::to_string(bytes.size() - 12) + " ignored"});
}

TEST(TckReader, chunksHoldWholeStreamlinesUpToMaxPoints) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(200, 5);
  writeTractogram(dir.file("c.tck"), t, {});
  for (size_t max_points : {1, 10, 100, 1000000}) {
    const ReadResult r = readAll(dir.file("c.tck"), {}, max_points);
    expectSameStreamlines(r.tractogram, t);
  }
}

TEST(TckReader, readsStreamlinesThatSpanReadBuffers) {
  // Several MiB, so streamlines, separators and samples straddle the reader's
  // 1 MiB buffer refills; one streamline alone is longer than a buffer.
  test::TempDir dir;
  Tractogram t = test::smallTractogram(3000, 12, true);
  t.per_streamline.clear();
  std::vector<float> longest;
  for (int i = 0; i < 3 * 150000; ++i) longest.push_back(float(i % 1000) * 0.01f);
  t.addStreamline(longest.data(), longest.size() / 3);
  t.addStreamline(nullptr, 0);
  t.per_point[0].values.resize(t.pointCount(), 0.75f);
  for (const std::string dt : {"Float32LE", "Float64BE"}) {
    const std::string path = dir.file("big" + dt + ".tck");
    writeTractogram(path, t, {.per_point = {{"fa"}}}, {.tck_datatype = dt});
    const std::string tsf = dir.file("big" + dt + "_fa.tsf");
    const ReadResult r = readAll(path, {tsf}, 100000);
    expectSameStreamlines(r.tractogram, t);
    EXPECT_EQ(r.tractogram.per_point[0].values, t.per_point[0].values);
    EXPECT_TRUE(r.warnings.empty());
    // Cut inside the long streamline, and one byte short of the end.
    const std::string bytes = test::readBytes(path);
    for (size_t cut : {bytes.size() - 1000000, bytes.size() - 1}) {
      test::writeBytes(dir.file("cut.tck"), bytes.substr(0, cut));
      const ReadResult c = readAll(dir.file("cut.tck"), {}, 100000);
      const bool in_long = cut < bytes.size() - 1;
      const size_t kept = in_long ? 3000 : t.streamlineCount();
      ASSERT_EQ(c.tractogram.streamlineCount(), kept);
      EXPECT_EQ(c.tractogram.offsets, std::vector<uint64_t>(t.offsets.begin(), t.offsets.begin() + kept + 1));
      ASSERT_EQ(c.warnings.size(), in_long ? 2u : 1u);
      // After the long streamline come its separator, the empty one's and the terminator.
      const size_t triplet = dt == "Float32LE" ? 12 : 24;
      const size_t long_start = bytes.size() - triplet * (150000 + 3);
      const size_t partial = in_long ? (cut - long_start) / triplet : 0;
      EXPECT_EQ(c.warnings[0], dir.file("cut.tck") + ": no terminator: file truncated at byte " + std::to_string(cut) +
                                   ", last partial streamline of " + std::to_string(partial) + " points dropped");
    }
  }
}

// --- writer and round trips ------------------------------------------------

TEST(TckRoundTrip, isExactForEveryDatatype) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(60, 3);
  for (const std::string dt : {"Float32LE", "Float32BE", "Float64LE", "Float64BE"}) {
    WriterOptions options;
    options.tck_datatype = dt;
    const std::string path = dir.file(dt + ".tck");
    std::vector<std::string> warnings;
    writeTractogram(path, t, {}, options, &warnings);
    EXPECT_TRUE(warnings.empty());
    const ReadResult r = readAll(path, {}, 500);
    expectSameStreamlines(r.tractogram, t);
    EXPECT_EQ(r.header.property("datatype"), dt);
    EXPECT_EQ(r.header.declared_streamlines, 60);
    EXPECT_TRUE(r.warnings.empty());
    // Points, separators, terminator and nothing else after the header.
    const size_t sample = dt.rfind("Float64", 0) == 0 ? 8 : 4;
    const uint64_t offset = std::stoull(r.header.property("file").substr(2));
    EXPECT_EQ(std::filesystem::file_size(path), offset + sample * 3 * (t.pointCount() + t.streamlineCount() + 1));
  }
}

TEST(TckRoundTrip, keepsZeroLengthStreamlinesAndEmptyFiles) {
  test::TempDir dir;
  const Tractogram t = fromSamples({{}, {1, 2, 3}, {}});
  writeTractogram(dir.file("z.tck"), t, {});
  expectSameStreamlines(readAll(dir.file("z.tck")).tractogram, t);
  writeTractogram(dir.file("e.tck"), Tractogram{}, {});
  const ReadResult r = readAll(dir.file("e.tck"));
  EXPECT_EQ(r.tractogram.streamlineCount(), 0u);
  EXPECT_EQ(r.header.declared_streamlines, 0);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(TckWriter, streamsChunksAndPatchesTheCountInPlace) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(30, 8);
  const std::string path = dir.file("s.tck");
  auto writer = createTckWriter(path, {}, {});
  // Nothing under the final name until finish().
  for (size_t i = 0; i < 30; i += 7) {
    Tractogram chunk;
    for (size_t j = i; j < std::min<size_t>(i + 7, 30); ++j) chunk.addStreamline(t.point(t.offsets[j]), t.pointsIn(j));
    writer->write(chunk);
    EXPECT_FALSE(std::filesystem::exists(path));
  }
  writer->finish();
  const std::string bytes = test::readBytes(path);
  const size_t end = bytes.find("\nEND\n");
  ASSERT_NE(end, std::string::npos);
  const std::string header = bytes.substr(0, end + 5);
  EXPECT_EQ(header, "mrtrix tracks\ndatatype: Float32LE\ncount: 00000000000000000030\nfile: . " +
                        std::to_string(header.size()) + "\nEND\n");
  expectSameStreamlines(readAll(path).tractogram, t);
}

TEST(TckWriter, carriesPropertiesExceptTheKeysItOwns) {
  test::TempDir dir;
  TractogramHeader like;
  like.properties = {{"command_history", "tckgen in.mif out.tck"},
                     {"datatype", "Float64BE"},
                     {"roi", "seed a.nii\nmask b.nii"},  // MRtrix joins repeated keys with newlines
                     {"count", "77"},
                     {"total_count", "80"},
                     {"file", ". 999"},
                     {"bad:key", "x"},
                     {"step_size", "0.5"}};
  const std::string path = dir.file("p.tck");
  std::vector<std::string> warnings;
  writeTractogram(path, fromSamples(kThree), like, {}, &warnings);
  EXPECT_EQ(warnings,
            std::vector<std::string>{"header key 'bad:key' cannot be stored in a track file header; dropped"});
  const ReadResult r = readAll(path);
  const std::vector<std::pair<std::string, std::string>> expected = {{"command_history", "tckgen in.mif out.tck"},
                                                                     {"roi", "seed a.nii"},
                                                                     {"roi", "mask b.nii"},
                                                                     {"step_size", "0.5"},
                                                                     {"datatype", "Float32LE"},
                                                                     {"count", "00000000000000000003"},
                                                                     {"file", r.header.property("file")}};
  EXPECT_EQ(r.header.properties, expected);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(TckWriter, refusesToOverwriteWithoutTheFlag) {
  test::TempDir dir;
  const std::string path = dir.file("o.tck");
  test::writeBytes(path, "precious");
  expectError(errorOf([&] { writeTractogram(path, fromSamples(kThree), {}); }), path, "exists");
  EXPECT_EQ(test::readBytes(path), "precious");
  // A sibling .tsf that would be replaced counts too, and nothing is created.
  const std::string other = dir.file("n.tck");
  test::writeBytes(dir.file("n_fa.tsf"), "precious");
  expectError(errorOf([&] { writeTractogram(other, test::smallTractogram(3, 1, true), {.per_point = {{"fa"}}}); }),
              dir.file("n_fa.tsf"), "exists");
  EXPECT_FALSE(std::filesystem::exists(other));
  EXPECT_EQ(fileCount(dir), 2u);

  WriterOptions force;
  force.overwrite = true;
  writeTractogram(path, fromSamples(kThree), {}, force);
  expectSameStreamlines(readAll(path).tractogram, fromSamples(kThree));
}

TEST(TckWriter, leavesNoTempFilesBehindAfterAFailedWrite) {
  test::TempDir dir;
  TractogramHeader like;
  like.per_point = {{"fa"}};
  Tractogram bad = test::smallTractogram(4, 2, true);
  bad.positions[3 * bad.offsets[1] + 1] = kNaN;
  const std::string path = dir.file("f.tck");
  expectError(errorOf([&] { writeTractogram(path, bad, like); }), path,
              "streamline 1 point 0 has a non-finite coordinate");
  EXPECT_EQ(fileCount(dir), 0u);
  // A writer dropped without finish() leaves nothing either.
  {
    auto writer = createTckWriter(path, like, {});
    writer->write(test::smallTractogram(4, 2, true));
  }
  EXPECT_EQ(fileCount(dir), 0u);
  expectError(errorOf([&] { createTckWriter(path, like, {.tck_datatype = "Float16LE"}); }), path,
              "unknown tck datatype 'Float16LE'");
}

TEST(TckWriter, warnsOnceForEachThingTckCannotCarry) {
  test::TempDir dir;
  Tractogram t = test::smallTractogram(5, 4, true);  // per-streamline "weight", per-point "fa"
  t.per_point.push_back({"rgb", 3, "uint8", std::vector<float>(3 * t.pointCount(), 0.5f)});
  TractogramHeader like;
  like.per_streamline = {{"weight"}};
  like.per_point = {{"fa"}, {"rgb", 3, "uint8", {}}};
  like.groups = {{"CST_left", {0, 1}}, {"AF", {2}}};
  like.space.known = true;
  like.space.dimensions = {91, 109, 91};
  const std::string path = dir.file("w.tck");
  std::vector<std::string> warnings;
  auto writer = createTckWriter(path, like, {});
  writer->write(t);
  writer->write(t);  // a second chunk adds no warnings
  writer->finish();
  EXPECT_EQ(writer->warnings(),
            (std::vector<std::string>{
                "per-streamline array 'weight' dropped: .tck cannot store per-streamline data",
                "per-point array 'rgb' (3 components) dropped: a .tsf holds one value per point",
                "2 groups dropped (.tck has no groups): CST_left, AF",
                "voxel grid of the reference image (91x109x91 voxels) dropped: .tck stores world coordinates only"}));
  // The one-component array went to its .tsf.
  EXPECT_TRUE(std::filesystem::exists(dir.file("w_fa.tsf")));
  EXPECT_EQ(fileCount(dir), 2u);
}

// --- .tsf ---------------------------------------------------------------

TEST(TckTsf, attachesScalarsAsPerPointArrays) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = {{1, 2, 3, 4, 5, 6}, {}, {7, 8, 9}};
  test::writeBytes(dir.file("t.tck"), buildTrackFile(spec));
  test::writeBytes(dir.file("fa.tsf"), buildTrackFile(tsfSpec({{0.5f, 0.25f}, {}, {0.125f}})));
  TrackSpec md = tsfSpec({{1e-3f, 2e-3f}, {}, {3e-3f}});
  md.datatype = "Float64BE";
  test::writeBytes(dir.file("md.TSF"), buildTrackFile(md));
  const ReadResult r = readAll(dir.file("t.tck"), {dir.file("fa.tsf"), dir.file("md.TSF")}, 1);
  EXPECT_TRUE(r.warnings.empty());
  ASSERT_EQ(r.tractogram.per_point.size(), 2u);
  EXPECT_EQ(r.tractogram.per_point[0].name, "fa");
  EXPECT_EQ(r.tractogram.per_point[0].values, (std::vector<float>{0.5f, 0.25f, 0.125f}));
  EXPECT_EQ(r.tractogram.per_point[1].name, "md");
  EXPECT_EQ(r.tractogram.per_point[1].dtype, "float64");
  EXPECT_EQ(r.tractogram.per_point[1].values, (std::vector<float>{1e-3f, 2e-3f, 3e-3f}));
}

TEST(TckTsf, acceptsScalarsWithoutTerminatorAsMrtrixWritesThem) {
  // MRtrix 3.0 tcksample ends its .tsf after the last NaN separator.
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;
  test::writeBytes(dir.file("t.tck"), buildTrackFile(spec));
  TrackSpec scalars = tsfSpec({{1, 2}, {3}, {4, 5, 6}});
  scalars.terminator = false;
  const std::string tsf = dir.file("s.tsf");
  const std::string bytes = buildTrackFile(scalars);
  test::writeBytes(tsf, bytes);
  ReadResult r = readAll(dir.file("t.tck"), {tsf});
  EXPECT_EQ(r.tractogram.per_point[0].values, (std::vector<float>{1, 2, 3, 4, 5, 6}));
  EXPECT_TRUE(r.warnings.empty());
  // Stray bytes of a cut sample are worth a warning.
  test::writeBytes(tsf, bytes + "\x01\x02");
  r = readAll(dir.file("t.tck"), {tsf});
  EXPECT_EQ(r.tractogram.per_point[0].values, (std::vector<float>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(r.warnings, std::vector<std::string>{tsf +
                                                 ": file ends inside a sample after its last streamline "
                                                 "(truncated at byte " +
                                                 std::to_string(bytes.size()) + "); the stray bytes are ignored"});
}

TEST(TckTsf, rejectsScalarsThatDoNotMatchTheTractogram) {
  test::TempDir dir;
  TrackSpec spec;
  spec.streamlines = kThree;  // 2, 1 and 3 points
  test::writeBytes(dir.file("t.tck"), buildTrackFile(spec));
  const std::string tsf = dir.file("s.tsf");
  struct Case {
    Samples values;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {{{1, 2}, {3, 4}, {5, 6, 7}},
       "streamline 1 has more values than points (the tractogram's streamline has 1 points)"},
      {{{1, 2}, {3}, {5, 6}}, "streamline 2 has 2 values (the tractogram's streamline has 3 points)"},
      {{{1, 2}, {3}}, "the file ends after 2 streamlines, but the tractogram has more (streamline 2 has 3 points)"},
      {{{1, 2}, {3}, {5, 6, 7}, {8}}, "holds more streamlines than the 3 of the tractogram"},
  };
  for (const auto& c : cases) {
    test::writeBytes(tsf, buildTrackFile(tsfSpec(c.values)));
    expectError(errorOf([&] { readAll(dir.file("t.tck"), {tsf}); }), tsf, c.needle);
  }
  // A truncated .tsf names where it stops.
  std::string cut = buildTrackFile(tsfSpec({{1, 2}, {3}, {5, 6, 7}}));
  cut.resize(cut.size() - 12);
  test::writeBytes(tsf, cut);
  expectError(errorOf([&] { readAll(dir.file("t.tck"), {tsf}); }), tsf,
              "byte " + std::to_string(cut.size()) + ": file truncated inside streamline 2 after 2 values");
  // A tractogram given as scalars.
  test::writeBytes(tsf, buildTrackFile(spec));
  expectError(errorOf([&] { openTck(dir.file("t.tck"), {tsf}); }), tsf, "is a tractogram (.tck), not a track scalar");
}

TEST(TckTsf, perPointArraysRoundTripThroughSiblingFiles) {
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(25, 6, true);
  TractogramHeader like;
  like.per_point = {{"fa"}};
  like.per_streamline = {{"weight"}};
  like.properties = {{"timestamp", "1795325206.951849699"}};
  for (const std::string dt : {"Float32LE", "Float64BE"}) {
    const std::string path = dir.file("rt" + dt + ".tck");
    writeTractogram(path, t, like, {.tck_datatype = dt});
    const std::string tsf = dir.file("rt" + dt + "_fa.tsf");
    const ReadResult r = readAll(path, {tsf});
    expectSameStreamlines(r.tractogram, t);
    ASSERT_EQ(r.tractogram.per_point.size(), 1u);
    EXPECT_EQ(r.tractogram.per_point[0].name, "rt" + dt + "_fa");
    EXPECT_EQ(r.tractogram.per_point[0].values, t.per_point[0].values);
    EXPECT_TRUE(r.warnings.empty());
  }
  // writeTsf on its own, checked against a tsf with another timestamp.
  const std::string lone = dir.file("lone.tsf");
  writeTsf(lone, t, "fa", {.properties = {{"timestamp", "1"}}});
  const ReadResult r = readAll(dir.file("rtFloat32LE.tck"), {lone});
  EXPECT_EQ(r.tractogram.per_point[0].values, t.per_point[0].values);
  EXPECT_EQ(r.warnings,
            std::vector<std::string>{lone + ": timestamp 1 differs from the tractogram's "
                                            "1795325206.951849699; it may have been made from another .tck"});
}

TEST(TckTsf, writerDropsAnArrayHoldingNaNButKeepsTheTractogram) {
  test::TempDir dir;
  Tractogram t = test::smallTractogram(5, 2, true);
  t.per_streamline.clear();
  t.per_point[0].values[3] = kNaN;
  std::vector<std::string> warnings;
  writeTractogram(dir.file("n.tck"), t, {.per_point = {{"fa"}}}, {}, &warnings);
  EXPECT_EQ(warnings, std::vector<std::string>{"per-point array 'fa' dropped: it holds nan, which a .tsf cannot store "
                                               "(NaN and Inf are its separators)"});
  EXPECT_FALSE(std::filesystem::exists(dir.file("n_fa.tsf")));
  expectSameStreamlines(readAll(dir.file("n.tck")).tractogram, t);
  EXPECT_EQ(fileCount(dir), 1u);
}

// --- nibabel as the outside reference ---------------------------------------

// Looked up once: each lookup starts Python and imports nibabel.
const std::string& python() {
  static const std::string path = test::pythonWithNibabel();
  return path;
}

// Runs the reference script; returns its JSON lines (nibabel may also warn on stderr).
std::vector<nlohmann::json> runReference(const std::string& args) {
  const auto r = test::runCommand(python() + " " + test::toolPath("tck_reference.py") + " " + args);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::vector<nlohmann::json> out;
  size_t begin = 0;
  while (begin < r.output.size()) {
    const size_t end = std::min(r.output.find('\n', begin), r.output.size());
    if (r.output[begin] == '{') out.push_back(nlohmann::json::parse(r.output.substr(begin, end - begin)));
    begin = end + 1;
  }
  return out;
}

Tractogram fromReference(const nlohmann::json& j) {
  Tractogram t;
  const auto lengths = j["lengths"].get<std::vector<size_t>>();
  const auto points = j["points"].get<std::vector<double>>();
  size_t at = 0;
  for (size_t n : lengths) {
    std::vector<float> xyz(points.begin() + at, points.begin() + at + 3 * n);  // float32 values, exact
    t.addStreamline(xyz.data(), n);
    at += 3 * n;
  }
  EXPECT_EQ(at, points.size());
  return t;
}

TEST(TckNibabel, readsFilesNibabelWrote) {
  if (python().empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel";
  test::TempDir dir;
  const std::string path = dir.file("nib.tck");
  const auto refs = runReference("write " + path + " 11 57");
  ASSERT_EQ(refs.size(), 1u);
  const nlohmann::json& ref = refs[0];
  const ReadResult r = readAll(path, {}, 100);
  expectSameStreamlines(r.tractogram, fromReference(ref));
  EXPECT_EQ(r.tractogram.streamlineCount(), 57u);
  EXPECT_EQ(r.header.declared_streamlines, 57);
  EXPECT_EQ(r.header.property("command_history"), "tck_reference.py write");
  EXPECT_TRUE(r.warnings.empty());
}

TEST(TckNibabel, nibabelReadsWhatWeWrite) {
  if (python().empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel";
  test::TempDir dir;
  const Tractogram t = test::smallTractogram(73, 9);
  TractogramHeader like;
  like.properties = {{"command_history", "fibscope convert a.trk b.tck"}, {"step_size", "0.5"}};
  // nibabel reads float32 only, in either byte order.
  const std::vector<std::string> datatypes = {"Float32LE", "Float32BE"};
  std::string paths;
  for (const auto& dt : datatypes) {
    writeTractogram(dir.file(dt + ".tck"), t, like, {.tck_datatype = dt});
    paths += " " + dir.file(dt + ".tck");
  }
  const auto refs = runReference("read" + paths);
  ASSERT_EQ(refs.size(), datatypes.size());
  for (size_t i = 0; i < datatypes.size(); ++i) {
    const nlohmann::json& ref = refs[i];
    EXPECT_EQ(ref["count"].get<size_t>(), 73u);
    expectSameStreamlines(fromReference(ref), t);
    EXPECT_EQ(ref["header"]["command_history"], "fibscope convert a.trk b.tck");
    EXPECT_EQ(ref["header"]["step_size"], "0.5");
    EXPECT_EQ(ref["header"]["count"], "00000000000000000073");
    EXPECT_EQ(ref["header"]["datatype"], datatypes[i]);
  }
}

}  // namespace
}  // namespace fibscope
