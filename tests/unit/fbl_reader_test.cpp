// Reading .fbl files as tractograms (openFbl) and `fibscope decompress`.
//
// Files are written the way `fibscope compress` writes them (FblWriter +
// encodeTractogram, sections fiblets, fiber_first_fiblet, fiber_length_mm,
// dps/<name>, source); the reference for the decoded points is
// FibletDecoder::decodeAll of the same records (in the reader's order). Damage is tested two ways:
// raw bit flips and truncations (caught by the container's checksums and
// sizes), and tables tampered with and their checksums recomputed, so that
// the reader's own structural checks are what must catch them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "codec/codec_params.h"
#include "codec/fbl_codec.h"
#include "codec/fbl_file.h"
#include "codec/fbl_format.h"
#include "codec/fbl_reader.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "core/byte_order.h"
#include "core/checksum.h"
#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::TempDir;

struct Written {
  CodecParams params;
  EncodedFiblets fiblets;
};

double arcLength(const Tractogram& t, size_t s) {
  double length = 0;
  for (uint64_t i = t.offsets[s] + 1; i < t.offsets[s + 1]; ++i) {
    const float* a = t.point(i - 1);
    const float* b = t.point(i);
    length += std::sqrt(double(b[0] - a[0]) * (b[0] - a[0]) + double(b[1] - a[1]) * (b[1] - a[1]) +
                        double(b[2] - a[2]) * (b[2] - a[2]));
  }
  return length;
}

// What `fibscope compress` writes (see the task brief / docs/FBL_FORMAT.md).
// With per-point arrays: their "dpv/<name>" sections and the
// "fiber_first_point" table, whose second entry is off by
// `first_point_shift` (a lying table, checksums intact).
Written writeFbl(const std::string& path, const Tractogram& t, const TractogramHeader& like,
                 uint32_t points_per_fiblet = 60, int64_t first_point_shift = 0) {
  CodecParamOptions options;
  options.points_per_fiblet = points_per_fiblet;
  Written w;
  w.params = roundTripThroughFbl(chooseCodecParams(t, options));
  w.fiblets = encodeTractogram(t, w.params);
  FblHeaderFields fields = fblHeaderFor(w.params);
  fields.fiber_count = t.streamlineCount();
  fields.fiblet_count = w.fiblets.fibletCount();
  fields.point_count = t.pointCount();
  FblWriter writer(path, fields, /*overwrite=*/true);
  writer.writeSection({std::string(kFblSectionFiblets), FblDType::kUint32, 1}, w.fiblets.bytes.data(),
                      w.fiblets.bytes.size());
  std::vector<uint64_t> first(w.fiblets.fiber_first_fiblet.begin(), w.fiblets.fiber_first_fiblet.end());
  first.push_back(w.fiblets.fibletCount());
  writer.writeSection({std::string(kFblSectionFiberFirstFiblet), FblDType::kUint64, 1}, first.data(), first.size() * 8);
  std::vector<float> lengths;
  for (size_t s = 0; s < t.streamlineCount(); ++s) lengths.push_back(float(arcLength(t, s)));
  writer.writeSection({std::string(kFblSectionFiberLength), FblDType::kFloat32, 1}, lengths.data(), lengths.size() * 4);
  for (const DataArray& a : t.per_streamline)
    writer.writeSection({std::string(kFblSectionDpsPrefix) + a.name, FblDType::kFloat32, a.components}, a.values.data(),
                        a.values.size() * 4);
  if (!t.per_point.empty()) {
    std::vector<uint64_t> first_point(t.offsets.begin(), t.offsets.end());
    if (first_point.size() > 1) first_point[1] = uint64_t(int64_t(first_point[1]) + first_point_shift);
    writer.writeSection({std::string(kFblSectionFiberFirstPoint), FblDType::kUint64, 1}, first_point.data(),
                        first_point.size() * 8);
    for (const DataArray& a : t.per_point)
      writer.writeSection({std::string(kFblSectionDpvPrefix) + a.name, FblDType::kFloat32, a.components},
                          a.values.data(), a.values.size() * 4);
  }
  const std::string source = fblSourceJson(like);
  writer.writeSection({std::string(kFblSectionSource), FblDType::kUtf8, 1}, source.data(), source.size());
  writer.finish();
  return w;
}

TractogramHeader headerOf(const Tractogram& t, const std::string& format = "tck") {
  TractogramHeader h;
  h.path = "original." + format;
  h.format = format;
  for (const auto& a : t.per_streamline) h.per_streamline.push_back({a.name, a.components, a.dtype, {}});
  for (const auto& a : t.per_point) h.per_point.push_back({a.name, a.components, a.dtype, {}});
  return h;
}

// Reads everything through a reader, checking every chunk on the way.
Tractogram readAll(TractogramReader& reader, size_t max_points = size_t(1) << 20, size_t* chunks = nullptr) {
  Tractogram all, chunk;
  for (const auto& a : reader.header().per_streamline)
    all.per_streamline.push_back({a.name, a.components, a.dtype, {}});
  for (const auto& a : reader.header().per_point) all.per_point.push_back({a.name, a.components, a.dtype, {}});
  uint64_t previous_bytes = reader.bytesRead();
  size_t n = 0;
  while (reader.read(chunk, max_points)) {
    EXPECT_EQ(chunk.validate(), "");
    EXPECT_GE(chunk.streamlineCount(), 1u);
    EXPECT_GE(reader.bytesRead(), previous_bytes);
    previous_bytes = reader.bytesRead();
    all.append(chunk);
    ++n;
  }
  if (chunks) *chunks = n;
  return all;
}

Tractogram readFbl(const std::string& path, size_t max_points = size_t(1) << 20) {
  auto reader = openFbl(path);
  Tractogram all = readAll(*reader, max_points);
  EXPECT_EQ(reader->bytesRead(), reader->header().file_bytes);
  return all;
}

::testing::AssertionResult samePoints(const Tractogram& a, const Tractogram& b) {
  if (a.offsets != b.offsets) return ::testing::AssertionFailure() << "offsets differ";
  if (a.positions.size() != b.positions.size()) return ::testing::AssertionFailure() << "position counts differ";
  if (std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(float)) != 0) {
    for (size_t i = 0; i < a.positions.size(); ++i)
      if (std::memcmp(&a.positions[i], &b.positions[i], sizeof(float)) != 0)
        return ::testing::AssertionFailure()
               << "coordinate " << i << ": " << a.positions[i] << " vs " << b.positions[i];
  }
  return ::testing::AssertionSuccess();
}

// A few hundred phantom fibers at 0.5 mm, with its "bundle" array and header
// (space, MRtrix-style properties).
const Tractogram& phantomFibers(TractogramHeader* header = nullptr) {
  static Tractogram all;
  static TractogramHeader phantom_header;
  if (all.streamlineCount() == 0) {
    PhantomOptions options;
    options.streamlines = 120;
    options.step_mm = 0.5;
    options.seed = 11;
    options.threads = 1;
    auto reader = openPhantom(options);
    all = readAll(*reader);
    phantom_header = reader->header();
  }
  if (header) *header = phantom_header;
  return all;
}

// Recomputes every section checksum, the table and the header checksum
// after a deliberate edit, so that the edit reaches the structural checks.
void repairChecksums(std::string& b) {
  auto* p = reinterpret_cast<uint8_t*>(b.data());
  const uint32_t count = loadUnaligned<uint32_t>(p + fbl::header::kSectionCount);
  for (uint32_t i = 0; i < count; ++i) {
    uint8_t* e = p + fbl::kHeaderBytes + size_t(i) * fbl::kSectionEntryBytes;
    const uint64_t offset = loadUnaligned<uint64_t>(e + fbl::entry::kOffset);
    const uint64_t bytes = loadUnaligned<uint64_t>(e + fbl::entry::kBytes);
    storeUnaligned<uint32_t>(e + fbl::entry::kChecksum, crc32c(p + offset, size_t(bytes)));
  }
  storeUnaligned<uint32_t>(p + fbl::header::kTableChecksum,
                           crc32c(p + fbl::kHeaderBytes, size_t(count) * fbl::kSectionEntryBytes));
  storeUnaligned<uint32_t>(p + fbl::header::kHeaderChecksum, crc32c(p, fbl::header::kHeaderChecksum));
}

// The error message of reading `path` whole through openFbl ("" if none).
std::string readError(const std::string& path) {
  try {
    readFbl(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(FblReader, pointsEqualDecodeAllBitForBitWhateverTheChunkSize) {
  TempDir dir;
  const std::string path = dir.file("phantom.fbl");
  TractogramHeader header;
  const Tractogram& t = phantomFibers(&header);
  const Written w = writeFbl(path, t, header);
  for (const DecodeOrder order : {DecodeOrder::Sequential, DecodeOrder::Scan}) {
    const Tractogram expected = FibletDecoder(w.params).decodeAll(w.fiblets, order);
    ASSERT_EQ(expected.streamlineCount(), t.streamlineCount());
    for (const size_t max_points : {size_t(1), size_t(97), size_t(1000), size_t(4096), size_t(1) << 20}) {
      auto reader = openFbl(path, order);
      size_t chunks = 0;
      const Tractogram got = readAll(*reader, max_points, &chunks);
      EXPECT_EQ(reader->bytesRead(), reader->header().file_bytes);
      EXPECT_TRUE(samePoints(got, expected)) << "max_points " << max_points;
      if (max_points == 1) {
        EXPECT_EQ(chunks, t.streamlineCount());
      } else if (max_points == (size_t(1) << 20)) {
        EXPECT_EQ(chunks, 1u);
      }
    }
  }
  // The two orders agree to 1e-6 of the scene size, not bit for bit.
  const Tractogram seq = FibletDecoder(w.params).decodeAll(w.fiblets, DecodeOrder::Sequential);
  const Tractogram scan = FibletDecoder(w.params).decodeAll(w.fiblets, DecodeOrder::Scan);
  ASSERT_EQ(seq.positions.size(), scan.positions.size());
  double worst = 0;
  for (size_t i = 0; i < seq.positions.size(); ++i)
    worst = std::max(worst, std::fabs(double(seq.positions[i]) - scan.positions[i]));
  EXPECT_LE(worst, 1e-6 / double(w.params.scale));
}

TEST(FblReader, chunksHoldWholeFibersAndAboutMaxPoints) {
  TempDir dir;
  const std::string path = dir.file("small.fbl");
  const Tractogram t = test::smallTractogram(200, 3);
  writeFbl(path, t, headerOf(t));
  auto reader = openFbl(path);
  Tractogram chunk;
  size_t longest = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s) longest = std::max(longest, t.pointsIn(s));
  size_t fibers = 0;
  while (reader->read(chunk, 300)) {
    // Fibers are added until the chunk reaches max_points: it overshoots by
    // less than one fiber.
    EXPECT_LT(chunk.pointCount(), 300 + longest);
    for (size_t s = 0; s < chunk.streamlineCount(); ++s) EXPECT_EQ(chunk.pointsIn(s), t.pointsIn(fibers + s));
    fibers += chunk.streamlineCount();
  }
  EXPECT_EQ(fibers, t.streamlineCount());
  EXPECT_FALSE(reader->read(chunk, 300));
}

TEST(FblReader, smallerFibletsAndEmptyAndOnePointFibersDecodeAsEncoded) {
  TempDir dir;
  Tractogram t = test::smallTractogram(30, 5);
  // An empty fiber (no fiblet) and a one-point fiber in the middle.
  Tractogram odd;
  odd.addStreamline(t.point(0), 0);
  odd.addStreamline(t.point(3), 1);
  t.append(odd);
  t.append(test::smallTractogram(5, 6));
  for (const uint32_t n : {8u, 20u, 60u}) {
    const std::string path = dir.file("n" + std::to_string(n) + ".fbl");
    const Written w = writeFbl(path, t, headerOf(t), n);
    EXPECT_TRUE(samePoints(readFbl(path, 50), FibletDecoder(w.params).decodeAll(w.fiblets, DecodeOrder::Sequential)))
        << "N = " << n;
  }
}

TEST(FblReader, emptyTractogramHasNoStreamlines) {
  TempDir dir;
  const std::string path = dir.file("empty.fbl");
  Tractogram t;
  CodecParams params;  // chooseCodecParams needs points: write by hand
  FblHeaderFields fields = fblHeaderFor(roundTripThroughFbl(params));
  FblWriter writer(path, fields, true);
  writer.writeSection({std::string(kFblSectionFiblets), FblDType::kUint32, 1}, nullptr, 0);
  const uint64_t zero = 0;
  writer.writeSection({std::string(kFblSectionFiberFirstFiblet), FblDType::kUint64, 1}, &zero, 8);
  writer.writeSection({std::string(kFblSectionFiberLength), FblDType::kFloat32, 1}, nullptr, 0);
  const std::string source = fblSourceJson(headerOf(t, "trx"));
  writer.writeSection({std::string(kFblSectionSource), FblDType::kUtf8, 1}, source.data(), source.size());
  writer.finish();
  auto reader = openFbl(path);
  EXPECT_EQ(reader->header().declared_streamlines, 0);
  EXPECT_EQ(reader->header().format, "trx");
  Tractogram chunk;
  EXPECT_FALSE(reader->read(chunk));
  EXPECT_EQ(reader->bytesRead(), reader->header().file_bytes);
}

TEST(FblReader, headerDescribesTheOriginalAndPerStreamlineArraysComeBack) {
  TempDir dir;
  const std::string path = dir.file("phantom.fbl");
  TractogramHeader header;
  const Tractogram& t = phantomFibers(&header);
  ASSERT_EQ(t.per_streamline.size(), 1u);
  writeFbl(path, t, header);
  auto reader = openFbl(path);
  const TractogramHeader& h = reader->header();
  EXPECT_EQ(h.path, path);
  EXPECT_EQ(h.format, "phantom");
  EXPECT_EQ(h.file_bytes, std::filesystem::file_size(path));
  EXPECT_EQ(h.declared_streamlines, int64_t(t.streamlineCount()));
  EXPECT_EQ(h.declared_points, int64_t(t.pointCount()));
  EXPECT_TRUE(h.space.known);
  EXPECT_EQ(h.space.voxel_to_rasmm, header.space.voxel_to_rasmm);
  EXPECT_EQ(h.space.dimensions, header.space.dimensions);
  EXPECT_EQ(h.properties, header.properties);
  EXPECT_TRUE(h.per_point.empty());
  ASSERT_EQ(h.per_streamline.size(), 1u);
  EXPECT_EQ(h.per_streamline[0].name, "bundle");
  EXPECT_EQ(h.per_streamline[0].dtype, "uint8");
  const Tractogram got = readAll(*reader, 500);
  ASSERT_EQ(got.per_streamline.size(), 1u);
  EXPECT_EQ(got.per_streamline[0].values, t.per_streamline[0].values);

  // Three components survive too.
  Tractogram c = test::smallTractogram(40, 8);
  DataArray colour{"colour", 3, "float32", {}};
  for (size_t s = 0; s < c.streamlineCount(); ++s)
    for (int k = 0; k < 3; ++k) colour.values.push_back(float(s) + 0.25f * float(k));
  c.per_streamline.push_back(colour);
  writeFbl(dir.file("colour.fbl"), c, headerOf(c, "trx"));
  const Tractogram got_c = readFbl(dir.file("colour.fbl"), 64);
  ASSERT_EQ(got_c.per_streamline.size(), 1u);
  EXPECT_EQ(got_c.per_streamline[0].components, 3u);
  EXPECT_EQ(got_c.per_streamline[0].values, colour.values);
}

TEST(FblReader, readsTractogramsWrittenByTheIndependentPythonWriter) {
  if (!std::filesystem::exists("/usr/bin/python3")) GTEST_SKIP() << "/usr/bin/python3 is missing";
  TempDir dir;
  const std::string script = std::string(FIBSCOPE_TEST_TOOLS_DIR) + "/../../fuzz/seeds/fbl_fiblets.py";
  const auto r = test::runCommand("/usr/bin/python3 " + script + " " + dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // fiblets_n8.fbl: N = 8, fibers of fiblets {8, 3}, {}, {1}, {8, 8, 2};
  // fiblet i of fiber f starts at normalised (0.2 + 0.1 f + 0.01 i, 0.5,
  // 0.5); translation (-90, -126, -72) mm, 180 mm per unit; dps/weight =
  // 0, 1, 2, 3; a trk source with a 181 x 217 x 181 LAS grid.
  const std::string path = dir.file("fiblets_n8.fbl");
  auto reader = openFbl(path);
  const TractogramHeader& h = reader->header();
  EXPECT_EQ(h.format, "trk");
  EXPECT_EQ(h.space.dimensions, (std::array<int32_t, 3>{181, 217, 181}));
  EXPECT_EQ(h.space.voxel_order, "LAS");
  EXPECT_EQ(h.property("voxel_order"), "LAS");
  const Tractogram t = readAll(*reader, 5);
  EXPECT_EQ(reader->bytesRead(), h.file_bytes);
  EXPECT_EQ(t.offsets, (std::vector<uint64_t>{0, 11, 11, 12, 30}));
  ASSERT_EQ(t.per_streamline.size(), 1u);
  EXPECT_EQ(t.per_streamline[0].values, (std::vector<float>{0, 1, 2, 3}));
  const double quantum = 180.0 / 65535;
  auto expectStart = [&](uint64_t point, double x) {
    EXPECT_NEAR(t.point(point)[0], -90 + 180 * x, quantum) << point;
    EXPECT_NEAR(t.point(point)[1], -126 + 90.0, quantum) << point;
    EXPECT_NEAR(t.point(point)[2], -72 + 90.0, quantum) << point;
  };
  expectStart(0, 0.2);
  expectStart(8, 0.21);
  expectStart(11, 0.4);
  expectStart(12, 0.5);
  expectStart(20, 0.51);
  expectStart(28, 0.52);
  // Consecutive points inside a fiblet are delta = 0.5 mm apart (the
  // first segment: p1 - p0 = 0.002 units = 0.36 mm, stored exactly).
  for (uint64_t i = 2; i < 8; ++i) {
    const float* a = t.point(i - 1);
    const float* b = t.point(i);
    const double d = std::sqrt(double(b[0] - a[0]) * (b[0] - a[0]) + double(b[1] - a[1]) * (b[1] - a[1]) +
                               double(b[2] - a[2]) * (b[2] - a[2]));
    EXPECT_NEAR(d, 0.5, 1e-3) << i;
  }
}

TEST(DecompressCli, trkWithSpaceAndPropertiesComesBackWithTheSameHeader) {
  TempDir dir;
  TractogramHeader phantom_header;
  const Tractogram& t = phantomFibers(&phantom_header);
  const std::string trk = dir.file("original.trk");
  writeTractogram(trk, t, phantom_header);
  TractogramHeader original;
  const Tractogram from_trk = readTractogram(trk, &original);
  ASSERT_TRUE(original.space.known);
  ASSERT_FALSE(original.properties.empty());
  const std::string fbl = dir.file("brain.fbl");
  writeFbl(fbl, from_trk, original);
  const std::string out = dir.file("back.trk");
  const auto r = test::runFibscope("decompress " + fbl + " " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("wrote"), std::string::npos) << r.output;
  TractogramHeader back;
  const Tractogram decoded = readTractogram(out, &back);
  EXPECT_EQ(back.format, "trk");
  EXPECT_TRUE(back.space.known);
  EXPECT_EQ(back.space.voxel_to_rasmm, original.space.voxel_to_rasmm);
  EXPECT_EQ(back.space.dimensions, original.space.dimensions);
  EXPECT_EQ(back.space.voxel_sizes, original.space.voxel_sizes);
  EXPECT_EQ(back.space.voxel_order, original.space.voxel_order);
  EXPECT_EQ(back.properties, original.properties);
  ASSERT_EQ(back.per_streamline.size(), original.per_streamline.size());
  for (size_t a = 0; a < back.per_streamline.size(); ++a) {
    EXPECT_EQ(back.per_streamline[a].name, original.per_streamline[a].name);
    EXPECT_EQ(decoded.per_streamline[a].values, from_trk.per_streamline[a].values);
  }
  EXPECT_EQ(decoded.offsets, from_trk.offsets);
}

// The records and tables of a .fbl as EncodedFiblets, for decodeAll.
EncodedFiblets encodedFibletsOf(const std::string& path, CodecParams* params) {
  const FblFile f = FblFile::open(path);
  *params = codecParamsFromFbl(f.header(), path);
  EncodedFiblets e;
  e.record_bytes = params->recordBytes();
  const auto records = f.data(kFblSectionFiblets);
  e.bytes.assign(records.begin(), records.end());
  const auto first = f.array<uint64_t>(*f.find(kFblSectionFiberFirstFiblet));
  for (size_t i = 0; i + 1 < first.size(); ++i) {
    e.fiber_first_fiblet.push_back(uint32_t(first[i]));
    uint32_t points = 0;
    for (uint64_t k = first[i]; k < first[i + 1]; ++k)
      points += shader::fibletCount(e.record(k)[shader::fibletFlagsByte(params->points_per_fiblet)]);
    e.fiber_points.push_back(points);
  }
  return e;
}

TEST(DecompressCli, compressThenDecompressKeepsTheTrkHeaderAndDecodesAsDecodeAll) {
  TempDir dir;
  const std::string trk = dir.file("phantom.trk");
  ASSERT_EQ(test::runFibscope("phantom -n 40 --step 0.5 --threads 1 --seed 5 " + trk).exit_code, 0);
  const std::string fbl = dir.file("phantom.fbl");
  const auto c = test::runFibscope("compress --threads 2 --points 32 " + trk + " " + fbl);
  ASSERT_EQ(c.exit_code, 0) << c.output;
  CodecParams params;
  const EncodedFiblets encoded = encodedFibletsOf(fbl, &params);
  EXPECT_EQ(params.points_per_fiblet, 32u);
  const Tractogram expected = FibletDecoder(params).decodeAll(encoded, DecodeOrder::Sequential);
  TractogramHeader original;
  const Tractogram input = readTractogram(trk, &original);
  EXPECT_EQ(expected.offsets, input.offsets);
  for (const size_t max_points : {size_t(100), size_t(1) << 20})
    EXPECT_TRUE(samePoints(readFbl(fbl, max_points), expected)) << max_points;

  const std::string back = dir.file("back.trk");
  const auto d = test::runFibscope("decompress " + fbl + " " + back);
  ASSERT_EQ(d.exit_code, 0) << d.output;
  TractogramHeader header;
  const Tractogram decoded = readTractogram(back, &header);
  EXPECT_EQ(decoded.offsets, input.offsets);
  EXPECT_EQ(header.space.voxel_to_rasmm, original.space.voxel_to_rasmm);
  EXPECT_EQ(header.space.dimensions, original.space.dimensions);
  EXPECT_EQ(header.properties, original.properties);
  ASSERT_EQ(decoded.per_streamline.size(), input.per_streamline.size());
  for (size_t a = 0; a < decoded.per_streamline.size(); ++a)
    EXPECT_EQ(decoded.per_streamline[a].values, input.per_streamline[a].values);
  // trk stores voxel-mm floats: the decoded points come back within float
  // rounding of a few hundred mm.
  ASSERT_EQ(decoded.positions.size(), expected.positions.size());
  for (size_t i = 0; i < expected.positions.size(); ++i)
    ASSERT_NEAR(decoded.positions[i], expected.positions[i], 1e-4f) << i;
}

TEST(DecompressCli, tckAndTrxOutputsHoldTheDecodedPoints) {
  TempDir dir;
  const Tractogram t = test::smallTractogram(60, 9, /*with_data=*/true);
  const std::string fbl = dir.file("small.fbl");
  writeFbl(fbl, t, headerOf(t, "trk"));
  const Tractogram decoded = readFbl(fbl);
  for (const std::string ext : {"tck", "trx"}) {
    const std::string out = dir.file("out." + ext);
    const auto r = test::runFibscope("decompress " + fbl + " " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(samePoints(readTractogram(out), decoded)) << ext;
    // Never overwritten without --force.
    const auto again = test::runFibscope("decompress " + fbl + " " + out);
    EXPECT_EQ(again.exit_code, 2) << again.output;
    EXPECT_EQ(test::runFibscope("decompress --force " + fbl + " " + out).exit_code, 0);
  }
  // convert reads .fbl too.
  const auto r = test::runFibscope("convert " + fbl + " " + dir.file("conv.tck"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(samePoints(readTractogram(dir.file("conv.tck")), decoded));
}

TEST(DecompressCli, refusesAnInputThatIsNotFbl) {
  TempDir dir;
  const Tractogram t = test::smallTractogram(5);
  const std::string tck = dir.file("in.tck");
  writeTractogram(tck, t, headerOf(t));
  const auto r = test::runFibscope("decompress " + tck + " " + dir.file("out.trk") + " 2>" + dir.file("err"));
  EXPECT_EQ(r.exit_code, 2);
  const std::string err = test::readBytes(dir.file("err"));
  EXPECT_NE(err.find(tck), std::string::npos) << err;
  EXPECT_NE(err.find(".fbl"), std::string::npos) << err;
  EXPECT_NE(err.find("convert"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("out.trk")));
}

TEST(DecompressCli, infoShowsCodecFactsSectionsAndTheOriginal) {
  TempDir dir;
  Tractogram t = test::smallTractogram(50, 4, /*with_data=*/true);
  TractogramHeader like = headerOf(t, "trk");
  like.path = "/data/sub-01/brain.trk";
  const std::string fbl = dir.file("brain.fbl");
  const Written w = writeFbl(fbl, t, like, 20);
  const auto r = test::runFibscope("info " + fbl);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const std::string& expected :
       std::vector<std::string>{"fbl container", "N = 20", "delta", "alpha", "bytes per point", "fiblets",
                                "fiber_first_fiblet", "fiber_length_mm", "dps/weight", "source", "CRC ok",
                                "/data/sub-01/brain.trk", "dpv/fa", "fiber_first_point", std::to_string(t.pointCount()) + " points"})
    EXPECT_NE(r.output.find(expected), std::string::npos) << expected << "\n" << r.output;
  EXPECT_EQ(r.output.find("BAD"), std::string::npos) << r.output;

  const auto j = test::runFibscope("info --json " + fbl + " 2>/dev/null");
  ASSERT_EQ(j.exit_code, 0) << j.output;
  const auto doc = nlohmann::json::parse(j.output);
  ASSERT_EQ(doc.size(), 1u);
  const auto& f = doc[0].at("fbl");
  EXPECT_EQ(doc[0].at("format"), "fbl");
  EXPECT_EQ(doc[0].at("streamlines"), t.streamlineCount());
  EXPECT_EQ(f.at("points_per_fiblet"), 20);
  EXPECT_EQ(f.at("record_bytes"), w.params.recordBytes());
  EXPECT_DOUBLE_EQ(f.at("delta_mm").get<double>(), w.params.deltaMm());
  EXPECT_NEAR(f.at("alpha_deg").get<double>(), double(w.params.alpha) * 180 / 3.14159265358979, 1e-9);
  EXPECT_EQ(f.at("fibers"), t.streamlineCount());
  EXPECT_EQ(f.at("fiblets"), w.fiblets.fibletCount());
  EXPECT_EQ(f.at("points"), t.pointCount());
  EXPECT_EQ(f.at("file_bytes"), std::filesystem::file_size(fbl));
  EXPECT_DOUBLE_EQ(f.at("bytes_per_point").get<double>(),
                   double(std::filesystem::file_size(fbl)) / double(t.pointCount()));
  ASSERT_EQ(f.at("sections").size(), 7u);
  EXPECT_EQ(f.at("sections")[0].at("name"), "fiblets");
  EXPECT_EQ(f.at("sections")[0].at("dtype"), "uint32");
  EXPECT_EQ(f.at("sections")[3].at("name"), "dps/weight");
  for (const auto& s : f.at("sections")) EXPECT_TRUE(s.at("checksum_ok").get<bool>());
  EXPECT_EQ(f.at("source").at("format"), "trk");
  EXPECT_EQ(f.at("sections")[5].at("name"), "dpv/fa");
  EXPECT_TRUE(f.at("source").at("dropped_per_point").empty());
}

TEST(DecompressCli, infoShowsWhichSectionIsDamagedBeforeTheError) {
  TempDir dir;
  const Tractogram t = test::smallTractogram(20, 2);
  const std::string fbl = dir.file("bad.fbl");
  writeFbl(fbl, t, headerOf(t));
  const FblSection lengths = *FblFile::open(fbl).find(kFblSectionFiberLength);
  std::string bytes = test::readBytes(fbl);
  bytes[size_t(lengths.offset) + 2] ^= 0x10;
  test::writeBytes(fbl, bytes);
  const auto r = test::runFibscope("info " + fbl + " 2>" + dir.file("err"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("CRC BAD"), std::string::npos) << r.output;
  const std::string err = test::readBytes(dir.file("err"));
  EXPECT_NE(err.find("fiber_length_mm"), std::string::npos) << err;
}

// Which part of the file byte `at` belongs to, as the messages name it.
std::string partAt(const std::vector<FblSection>& sections, uint64_t at) {
  if (at < 8) return "not a .fbl file";  // the magic
  if (at < fbl::kHeaderBytes) return "header";
  for (const FblSection& s : sections)
    if (at >= s.offset && at < s.offset + s.bytes) return s.name;
  return "";
}

TEST(FblReader, everyFlippedBitAndTruncationIsOneLineErrorNamingThePathAndPart) {
  TempDir dir;
  const Tractogram t = test::smallTractogram(12, 7, /*with_data=*/true);
  const std::string good = dir.file("good.fbl");
  writeFbl(good, t, headerOf(t, "trk"));
  const std::vector<FblSection> sections = FblFile::open(good).sections();
  const std::string bytes = test::readBytes(good);
  const std::string path = dir.file("damaged.fbl");
  auto expectError = [&](const std::string& what, const std::string& part) {
    const std::string e = readError(path);
    ASSERT_FALSE(e.empty()) << what << " was read without an error";
    EXPECT_EQ(e.rfind(path, 0), 0u) << what << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << what << ": " << e;
    if (!part.empty()) {
      EXPECT_NE(e.find(part), std::string::npos) << what << " (in " << part << "): " << e;
    }
  };
  // Every 4th byte, a different bit each time (each is a file write and open).
  for (size_t at = 0; at < bytes.size(); at += 4) {
    std::string flipped = bytes;
    flipped[at] = char(flipped[at] ^ (1 << (at / 4 % 8)));
    test::writeBytes(path, flipped);
    expectError("bit flip at byte " + std::to_string(at), partAt(sections, at));
  }
  for (size_t length = 0; length < bytes.size(); length += 7) {
    test::writeBytes(path, bytes.substr(0, length));
    expectError("prefix of " + std::to_string(length) + " bytes", "");
  }
}

TEST(DecompressCli, damagedFilesExitWith2OneLineAndNoOutputLeftBehind) {
  TempDir dir;
  const Tractogram t = test::smallTractogram(15, 12, /*with_data=*/true);
  const std::string good = dir.file("good.fbl");
  writeFbl(good, t, headerOf(t, "trk"));
  const std::vector<FblSection> sections = FblFile::open(good).sections();
  const std::string bytes = test::readBytes(good);
  TempDir work;
  const std::string in = work.file("in.fbl");
  const std::string out = work.file("out.trk");
  const std::string err = work.file("stderr.txt");
  auto check = [&](const std::string& what, const std::string& part) {
    const auto r = test::runFibscope("decompress " + in + " " + out + " >/dev/null 2>" + err);
    EXPECT_EQ(r.exit_code, 2) << what << ": " << r.output;
    const std::string e = test::readBytes(err);
    EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 1) << what << ": " << e;
    EXPECT_NE(e.find(in), std::string::npos) << what << ": " << e;
    if (!part.empty()) {
      EXPECT_NE(e.find(part), std::string::npos) << what << " (in " << part << "): " << e;
    }
    // Nothing but the input and the captured stderr: no output, no temporary.
    size_t entries = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(work.path())) ++entries;
    EXPECT_EQ(entries, 2u) << what;
    std::filesystem::remove(out);
  };
  // About 150 flips and 40 truncations spread over the whole file (each a
  // process start, a few ms).
  const size_t flip_stride = bytes.size() / 150 + 1;
  for (size_t at = 0; at < bytes.size(); at += flip_stride) {
    std::string flipped = bytes;
    flipped[at] = char(flipped[at] ^ (0x80 >> (at % 8)));
    test::writeBytes(in, flipped);
    check("bit flip at byte " + std::to_string(at), partAt(sections, at));
  }
  for (size_t length = 0; length < bytes.size(); length += bytes.size() / 40 + 1) {
    test::writeBytes(in, bytes.substr(0, length));
    check("prefix of " + std::to_string(length) + " bytes", "");
  }
}

// Tampered-with tables whose checksums were recomputed: the reader's own
// checks must name what is wrong.
class FblTampered : public ::testing::Test {
 protected:
  void SetUp() override {
    t_ = test::smallTractogram(25, 21, /*with_data=*/true);
    // The per-fiber array only: a per-point one would report a tampered
    // point count as its own length (FblPointData covers those sections).
    t_.per_point.clear();
    // Long enough fibers that some have several fiblets at N = 8.
    written_ = writeFbl(good_, t_, headerOf(t_, "trk"), 8);
    const FblFile f = FblFile::open(good_);
    sections_ = f.sections();
    bytes_ = test::readBytes(good_);
    // A fiber with at least three fiblets.
    const auto& first = written_.fiblets.fiber_first_fiblet;
    for (size_t s = 0; s < first.size(); ++s) {
      const uint64_t next = s + 1 < first.size() ? first[s + 1] : written_.fiblets.fibletCount();
      if (next - first[s] >= 3) {
        fiber_ = s;
        break;
      }
    }
    ASSERT_GE(fiber_, 1u);
  }
  uint8_t* at(std::string_view section, uint64_t byte) {
    for (const FblSection& s : sections_)
      if (s.name == section) return reinterpret_cast<uint8_t*>(bytes_.data()) + s.offset + byte;
    ADD_FAILURE() << "no section " << section;
    return nullptr;
  }
  uint8_t* flags(uint64_t fiblet) {
    return at(kFblSectionFiblets, fiblet * written_.params.recordBytes() + shader::fibletFlagsByte(8));
  }
  uint64_t firstFiblet(size_t fiber) const { return written_.fiblets.fiber_first_fiblet[fiber]; }
  // Repairs the checksums, writes the file and returns the reader's error.
  std::string errorAfterRepair() {
    repairChecksums(bytes_);
    test::writeBytes(path_, bytes_);
    return readError(path_);
  }

  TempDir dir_;
  const std::string good_ = dir_.file("good.fbl");
  const std::string path_ = dir_.file("tampered.fbl");
  Tractogram t_;
  Written written_;
  std::vector<FblSection> sections_;
  std::string bytes_;
  size_t fiber_ = 0;
};

#define EXPECT_MESSAGE(message, ...)                                                \
  do {                                                                              \
    const std::string m = (message);                                                \
    EXPECT_EQ(m.rfind(path_, 0), 0u) << m;                                          \
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;                                \
    for (const std::string& part : std::initializer_list<std::string>{__VA_ARGS__}) \
      EXPECT_NE(m.find(part), std::string::npos) << part << ": " << m;              \
  } while (0)

TEST_F(FblTampered, unchangedFileReadsAfterRepair) { EXPECT_EQ(errorAfterRepair(), ""); }

TEST_F(FblTampered, decreasingFirstFibletTableIsNamed) {
  // Fiber fiber_ + 1 starts before fiber_ does.
  storeUnaligned<uint64_t>(at(kFblSectionFiberFirstFiblet, 8 * (fiber_ + 1)), firstFiblet(fiber_) - 1);
  EXPECT_MESSAGE(errorAfterRepair(), "fiber_first_fiblet", "fiber " + std::to_string(fiber_) + " starts", "decrease");
}

TEST_F(FblTampered, firstFibletTablePastTheRecordsIsNamed) {
  storeUnaligned<uint64_t>(at(kFblSectionFiberFirstFiblet, 8 * (fiber_ + 1)), uint64_t(1) << 40);
  EXPECT_MESSAGE(errorAfterRepair(), "fiber_first_fiblet", "fiber " + std::to_string(fiber_) + " ends", "past the");
}

TEST_F(FblTampered, tableEndsThatDisagreeWithTheHeaderAreNamed) {
  storeUnaligned<uint64_t>(at(kFblSectionFiberFirstFiblet, 0), 1);
  EXPECT_MESSAGE(errorAfterRepair(), "fiber_first_fiblet", "fiber 0 starts at fiblet 1");
  bytes_ = test::readBytes(good_);
  storeUnaligned<uint64_t>(at(kFblSectionFiberFirstFiblet, 8 * t_.streamlineCount()), 3);
  EXPECT_MESSAGE(errorAfterRepair(), "fiber_first_fiblet", "last entry 3");
}

TEST_F(FblTampered, missingBeginsFlagIsNamed) {
  const uint64_t fiblet = firstFiblet(fiber_);
  *flags(fiblet) &= uint8_t(~shader::kFibletFlagBegins);
  EXPECT_MESSAGE(errorAfterRepair(), "fiblets", "fiblet " + std::to_string(fiblet), "fiber " + std::to_string(fiber_),
                 "begins-fiber flag missing");
}

TEST_F(FblTampered, flagsInsideAFiberAreNamed) {
  const uint64_t middle = firstFiblet(fiber_) + 1;
  *flags(middle) |= uint8_t(shader::kFibletFlagBegins);
  EXPECT_MESSAGE(errorAfterRepair(), "fiblet " + std::to_string(middle), "begins-fiber flag set");
  bytes_ = test::readBytes(good_);
  *flags(middle) |= uint8_t(shader::kFibletFlagEnds);
  EXPECT_MESSAGE(errorAfterRepair(), "fiblet " + std::to_string(middle), "ends-fiber flag set");
  bytes_ = test::readBytes(good_);
  *flags(firstFiblet(fiber_ + 1) - 1) &= uint8_t(~shader::kFibletFlagEnds);
  EXPECT_MESSAGE(errorAfterRepair(), "fiblet " + std::to_string(firstFiblet(fiber_ + 1) - 1),
                 "ends-fiber flag missing");
}

TEST_F(FblTampered, pointCountOutsideOneToNIsNamed) {
  const uint64_t fiblet = firstFiblet(fiber_) + 1;
  *flags(fiblet) &= 3;  // count 0
  EXPECT_MESSAGE(errorAfterRepair(), "fiblets", "fiblet " + std::to_string(fiblet), "point count 0 outside [1, 8]");
  bytes_ = test::readBytes(good_);
  *flags(fiblet) = uint8_t((*flags(fiblet) & 3) | (9 << 2));
  EXPECT_MESSAGE(errorAfterRepair(), "point count 9 outside [1, 8]");
}

TEST_F(FblTampered, headerPointCountThatDisagreesWithTheFibletsIsNamed) {
  auto setPointCount = [&](uint64_t count) {
    bytes_ = test::readBytes(good_);
    storeUnaligned<uint64_t>(reinterpret_cast<uint8_t*>(bytes_.data()) + fbl::header::kPointCount, count);
  };
  setPointCount(t_.pointCount() + 1);
  EXPECT_MESSAGE(errorAfterRepair(), "header", std::to_string(t_.pointCount() + 1) + " points",
                 "hold " + std::to_string(t_.pointCount()));
  setPointCount(t_.pointCount() - 1);
  EXPECT_MESSAGE(errorAfterRepair(), "header", std::to_string(t_.pointCount() - 1) + " points");
  setPointCount(uint64_t(1) << 50);
  EXPECT_MESSAGE(errorAfterRepair(), "header", "cannot be held");
}

TEST_F(FblTampered, dpsSectionsMustMatchTheSourceJson) {
  // Rename dps/weight to dps/wEight: a section not in the JSON, and a JSON
  // array without its section.
  uint8_t* entry = nullptr;
  for (size_t i = 0; i < sections_.size(); ++i)
    if (sections_[i].name == "dps/weight")
      entry = reinterpret_cast<uint8_t*>(bytes_.data()) + fbl::kHeaderBytes + i * fbl::kSectionEntryBytes;
  ASSERT_NE(entry, nullptr);
  entry[5] = 'E';
  EXPECT_MESSAGE(errorAfterRepair(), "source", "'weight'", "no section 'dps/weight'");

  // The JSON says 2 components where the section has 1.
  bytes_ = test::readBytes(good_);
  const FblSection& source = sections_.back();
  ASSERT_EQ(source.name, "source");
  std::string json(bytes_.data() + source.offset, size_t(source.bytes));
  const size_t c = json.find("\"components\":1", json.find("\"per_streamline\""));
  ASSERT_NE(c, std::string::npos) << json;
  bytes_[size_t(source.offset) + c + 13] = '2';
  EXPECT_MESSAGE(errorAfterRepair(), "dps/weight", "1 components", "says 2");

  // The JSON lists no array at all: dps/weight is unexplained.
  bytes_ = test::readBytes(good_);
  const size_t list = json.find("\"per_streamline\":[");
  ASSERT_NE(list, std::string::npos);
  const size_t end = json.find(']', list);
  std::string replaced = json.substr(0, list) + "\"per_streamline\":[]" + json.substr(end + 1);
  replaced.resize(json.size(), ' ');  // same length: JSON allows trailing spaces
  std::memcpy(bytes_.data() + source.offset, replaced.data(), replaced.size());
  EXPECT_MESSAGE(errorAfterRepair(), "dps/weight", "not among the per-streamline arrays");
}

TEST_F(FblTampered, malformedSourceJsonIsNamed) {
  const FblSection& source = sections_.back();
  bytes_[size_t(source.offset)] = '[';
  EXPECT_MESSAGE(errorAfterRepair(), "source");

  // An array named "we\nht" with 0 components: the message stays one line.
  bytes_ = test::readBytes(good_);
  std::string json(bytes_.data() + source.offset, size_t(source.bytes));
  const std::string before = R"({"components":1,"dtype":"float32","name":"weight"})";
  const std::string after = R"({"components":0,"dtype":"float32","name":"we\nht"})";
  const size_t at = json.find(before);
  ASSERT_NE(at, std::string::npos) << json;
  std::memcpy(bytes_.data() + source.offset + at, after.data(), after.size());
  EXPECT_MESSAGE(errorAfterRepair(), "source", "0 components");
}

// Per-point arrays (trk scalars, TRX dpv) are kept: "dpv/<name>" sections
// with the fibers' first points, read back value for value, written back
// by decompress to trk and TRX, and a table of first points that does not
// match the fiblets' counts is one line naming the section.
TEST(FblPointData, perPointArraysComeBackAndALyingFirstPointTableIsOneLine) {
  TempDir dir;
  const Tractogram t = test::smallTractogram(40, 5, /*with_data=*/true);
  const std::string fbl = dir.file("scalars.fbl");
  writeFbl(fbl, t, headerOf(t, "trk"));
  {
    auto reader = openFbl(fbl);
    ASSERT_EQ(reader->header().per_point.size(), 1u);
    EXPECT_EQ(reader->header().per_point[0].name, "fa");
  }
  const Tractogram decoded = readFbl(fbl, 100);  // chunks of a few fibers: the values split with the points
  ASSERT_EQ(decoded.per_point.size(), 1u);
  EXPECT_EQ(decoded.per_point[0].values, t.per_point[0].values);
  for (const std::string ext : {"trk", "trx"}) {
    const std::string out = dir.file("back." + ext);
    const auto r = test::runFibscope("decompress " + fbl + " " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const Tractogram back = readTractogram(out);
    ASSERT_EQ(back.per_point.size(), 1u) << ext;
    EXPECT_EQ(back.per_point[0].name, "fa") << ext;
    ASSERT_EQ(back.per_point[0].values.size(), t.per_point[0].values.size()) << ext;
    for (size_t i = 0; i < back.per_point[0].values.size(); ++i)
      ASSERT_FLOAT_EQ(back.per_point[0].values[i], t.per_point[0].values[i]) << ext << " point " << i;
  }
  for (const int64_t shift : {int64_t(1), int64_t(-1)}) {
    const std::string bad = dir.file("lying" + std::to_string(shift) + ".fbl");
    writeFbl(bad, t, headerOf(t, "trk"), 60, shift);
    const std::string message = test::errorOf([&] { readFbl(bad); });
    EXPECT_NE(message.find(bad), std::string::npos) << message;
    EXPECT_NE(message.find("fiber_first_point"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace fibscope
