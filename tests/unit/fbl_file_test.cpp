// The .fbl container: round trips, layout, and corruption reports.
//
// Corruption tests flip bits and cut prefixes across a whole small file and
// require a one-line fibscope::Error that names the part hit (header,
// section table, the section, or padding). Hand-built tables check the
// structural rules (overlap, range, alignment) with valid checksums, so the
// structure checks themselves are exercised, not the checksums.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "codec/fbl_file.h"
#include "codec/fbl_format.h"
#include "core/byte_order.h"
#include "core/checksum.h"
#include "core/error.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::TempDir;

// Bit-at-a-time CRC-32C straight from the definition (reflected polynomial
// 0x82F63B78, init and final XOR 0xFFFFFFFF): the reference for both paths.
uint32_t crc32cBitwise(const uint8_t* p, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ ((c & 1u) ? 0x82F63B78u : 0u);
  }
  return ~c;
}

FblHeaderFields sampleFields() {
  FblHeaderFields f;
  f.codec_version = 3;
  f.fiber_count = 3;
  f.fiblet_count = 5;
  f.point_count = 123;
  f.points_per_fiblet = 60;
  f.fiblet_record_bytes = 64;
  f.translation[0] = -90.5;
  f.translation[1] = -126.25;
  f.translation[2] = -72.125;
  f.scale = 181.5;
  f.delta = 0.5 / 181.5;
  f.delta_mm = 0.5;
  f.alpha = 0.6981317007977318;
  f.v[0] = 0.267261f;
  f.v[1] = 0.534522f;
  f.v[2] = 0.801784f;
  return f;
}

struct Sample {
  std::vector<uint32_t> fiblets;
  std::vector<uint64_t> first{0, 2, 4, 5};
  std::vector<float> length{12.5f, 30.25f, 7.0f};
  std::vector<float> colour{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::string source = R"({"input":"brain.trk","format":"trk"})";
  Sample() {
    for (uint32_t i = 0; i < 5 * 16; ++i) fiblets.push_back(i * 2654435761u);
  }
};

// fiblets (in 7-byte appends), fiber_first_fiblet, fiber_length_mm,
// an empty section, dps/colour (3 components), source.
void writeSample(const std::string& path, const Sample& s, uint32_t capacity = 8) {
  FblWriter w(path, sampleFields(), /*overwrite=*/true, capacity);
  w.beginSection(std::string(kFblSectionFiblets), FblDType::kUint32);
  const auto* bytes = reinterpret_cast<const uint8_t*>(s.fiblets.data());
  const size_t total = s.fiblets.size() * 4;
  for (size_t at = 0; at < total; at += 7) w.append(bytes + at, std::min<size_t>(7, total - at));
  w.endSection();
  w.writeSection({std::string(kFblSectionFiberFirstFiblet), FblDType::kUint64, 1}, s.first.data(), s.first.size() * 8);
  w.writeSection({std::string(kFblSectionFiberLength), FblDType::kFloat32, 1}, s.length.data(), s.length.size() * 4);
  w.writeSection({"empty", FblDType::kFloat64, 2}, nullptr, 0);
  w.writeSection({"dps/colour", FblDType::kFloat32, 3}, s.colour.data(), s.colour.size() * 4);
  w.writeSection({std::string(kFblSectionSource), FblDType::kUtf8, 1}, s.source.data(), s.source.size());
  w.finish();
}

std::string errorOf(const std::string& path, bool verify = true) {
  try {
    FblFile f = FblFile::open(path);
    if (verify) f.verify();
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

// Recomputes the table and header checksums after a hand edit.
void fixChecksums(std::string& b) {
  auto* p = reinterpret_cast<uint8_t*>(b.data());
  const uint32_t count = loadUnaligned<uint32_t>(p + fbl::header::kSectionCount);
  storeUnaligned<uint32_t>(p + fbl::header::kTableChecksum,
                           crc32c(p + fbl::kHeaderBytes, size_t(count) * fbl::kSectionEntryBytes));
  storeUnaligned<uint32_t>(p + fbl::header::kHeaderChecksum, crc32c(p, fbl::header::kHeaderChecksum));
}

uint8_t* entryAt(std::string& b, size_t i) {
  return reinterpret_cast<uint8_t*>(b.data()) + fbl::kHeaderBytes + i * fbl::kSectionEntryBytes;
}

TEST(FblFile, crc32cMatchesPublishedVectors) {
  // CRC catalogue check value, and RFC 3720 appendix B.4 (iSCSI) vectors.
  const std::string check = "123456789";
  EXPECT_EQ(crc32c(check.data(), check.size()), 0xE3069283u);
  EXPECT_EQ(crc32cPortable(check.data(), check.size()), 0xE3069283u);
  uint8_t buffer[32];
  std::memset(buffer, 0, 32);
  EXPECT_EQ(crc32c(buffer, 32), 0x8A9136AAu);
  std::memset(buffer, 0xFF, 32);
  EXPECT_EQ(crc32c(buffer, 32), 0x62A8AB43u);
  for (int i = 0; i < 32; ++i) buffer[i] = static_cast<uint8_t>(i);
  EXPECT_EQ(crc32c(buffer, 32), 0x46DD794Eu);
  for (int i = 0; i < 32; ++i) buffer[i] = static_cast<uint8_t>(31 - i);
  EXPECT_EQ(crc32c(buffer, 32), 0x113FDB5Cu);
  EXPECT_EQ(crc32c(nullptr, 0), 0u);
}

TEST(FblFile, crc32cAgreesWithBitwiseDefinitionAtEveryLengthAndAlignment) {
  std::mt19937 rng(7);
  std::vector<uint8_t> data(600);
  for (auto& b : data) b = static_cast<uint8_t>(rng());
  for (size_t start = 0; start < 9; ++start) {
    for (size_t n = 0; n + start <= data.size(); n += (n < 40 ? 1 : 37)) {
      const uint32_t expected = crc32cBitwise(data.data() + start, n);
      ASSERT_EQ(crc32c(data.data() + start, n), expected) << start << " " << n;
      ASSERT_EQ(crc32cPortable(data.data() + start, n), expected) << start << " " << n;
      // Continuing from a split gives the CRC of the whole.
      const size_t half = n / 3;
      ASSERT_EQ(crc32c(data.data() + start + half, n - half, crc32c(data.data() + start, half)), expected);
      ASSERT_EQ(crc32cPortable(data.data() + start + half, n - half, crc32cPortable(data.data() + start, half)), expected);
    }
  }
}

TEST(FblFile, roundTripKeepsHeaderAndEverySection) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  const Sample s;
  writeSample(path, s);
  const FblFile f = FblFile::open(path);
  EXPECT_EQ(f.formatVersion(), 1u);
  const FblHeaderFields want = sampleFields();
  const FblHeaderFields& got = f.header();
  EXPECT_EQ(got.codec_version, want.codec_version);
  EXPECT_EQ(got.fiber_count, want.fiber_count);
  EXPECT_EQ(got.fiblet_count, want.fiblet_count);
  EXPECT_EQ(got.point_count, want.point_count);
  EXPECT_EQ(got.points_per_fiblet, want.points_per_fiblet);
  EXPECT_EQ(got.fiblet_record_bytes, want.fiblet_record_bytes);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(got.translation[i], want.translation[i]);
    EXPECT_EQ(got.v[i], want.v[i]);
  }
  EXPECT_EQ(got.scale, want.scale);
  EXPECT_EQ(got.delta, want.delta);
  EXPECT_EQ(got.delta_mm, want.delta_mm);
  EXPECT_EQ(got.alpha, want.alpha);

  ASSERT_EQ(f.sections().size(), 6u);
  const auto fiblets = f.array<uint32_t>(*f.find("fiblets"));
  EXPECT_EQ(std::vector<uint32_t>(fiblets.begin(), fiblets.end()), s.fiblets);
  const auto first = f.array<uint64_t>(*f.find("fiber_first_fiblet"));
  EXPECT_EQ(std::vector<uint64_t>(first.begin(), first.end()), s.first);
  const auto length = f.array<float>(*f.find("fiber_length_mm"));
  EXPECT_EQ(std::vector<float>(length.begin(), length.end()), s.length);
  const FblSection* empty = f.find("empty");
  ASSERT_NE(empty, nullptr);
  EXPECT_EQ(empty->element_count, 0u);
  EXPECT_EQ(empty->components, 2u);
  EXPECT_TRUE(f.data(*empty).empty());
  const FblSection* colour = f.find("dps/colour");
  ASSERT_NE(colour, nullptr);
  EXPECT_EQ(colour->components, 3u);
  EXPECT_EQ(colour->element_count, 3u);
  const auto c = f.array<float>(*colour);
  EXPECT_EQ(std::vector<float>(c.begin(), c.end()), s.colour);
  const auto text = f.data("source");
  EXPECT_EQ(std::string(text.begin(), text.end()), s.source);
  EXPECT_EQ(f.find("missing"), nullptr);
  EXPECT_NO_THROW(f.verify());
  EXPECT_NO_THROW(f.verify("fiblets"));
}

// fuzz/seeds/fbl.py writes .fbl files from docs/FBL_FORMAT.md with its own
// CRC-32C: an independent writer the reader must accept value for value.
TEST(FblFile, readsFilesWrittenByTheIndependentPythonWriter) {
  if (!std::filesystem::exists("/usr/bin/python3")) GTEST_SKIP() << "/usr/bin/python3 is missing";
  TempDir dir;
  const std::string script = std::string(FIBSCOPE_TEST_TOOLS_DIR) + "/../../fuzz/seeds/fbl.py";
  const auto result = test::runCommand("/usr/bin/python3 '" + script + "' '" + dir.path() + "'");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const FblFile f = FblFile::open(dir.file("sample.fbl"));
  f.verify();
  EXPECT_EQ(f.header().fiber_count, 2u);
  EXPECT_EQ(f.header().fiblet_count, 3u);
  EXPECT_EQ(f.header().point_count, 70u);
  EXPECT_EQ(f.header().points_per_fiblet, 60u);
  EXPECT_EQ(f.header().fiblet_record_bytes, 16u);
  EXPECT_EQ(f.header().translation[1], -126.0);
  EXPECT_EQ(f.header().scale, 180.0);
  EXPECT_EQ(f.header().alpha, 0.5);
  EXPECT_EQ(f.header().v[2], 0.75f);
  const auto first = f.array<uint64_t>(*f.find("fiber_first_fiblet"));
  EXPECT_EQ(std::vector<uint64_t>(first.begin(), first.end()), (std::vector<uint64_t>{0, 2, 3}));
  const auto colour = f.array<float>(*f.find("dps/colour"));
  EXPECT_EQ(std::vector<float>(colour.begin(), colour.end()), (std::vector<float>{1, 0, 0, 0, 1, 0}));
  const auto source = f.data("source");
  EXPECT_NE(std::string(source.begin(), source.end()).find("brain.trk"), std::string::npos);
  EXPECT_NO_THROW(FblFile::open(dir.file("empty.fbl")).verify());
  EXPECT_TRUE(FblFile::open(dir.file("no_sections.fbl")).sections().empty());
}

TEST(FblFile, everySectionAndTheFileEndAre64ByteAligned) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  const FblFile f = FblFile::open(path);
  EXPECT_EQ(f.fileBytes() % 64, 0u);
  for (const FblSection& s : f.sections()) {
    EXPECT_EQ(s.offset % 64, 0u) << s.name;
    EXPECT_EQ(reinterpret_cast<uintptr_t>(f.data(s).data()) % 64, 0u) << s.name;
  }
}

TEST(FblFile, typedAccessChecksTheDType) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  const FblFile f = FblFile::open(path);
  try {
    (void)f.array<float>(*f.find("fiblets"));
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("holds uint32, expected float32"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)f.data("nope"), Error);
}

// Which part of the sample file holds byte `i`, as the error must name it.
std::string partAt(const FblFile& f, uint64_t i) {
  if (i < 8) return "not a .fbl file";
  if (i < fbl::kHeaderBytes) return "header";
  uint64_t table_end = fbl::kHeaderBytes + 8 * fbl::kSectionEntryBytes;
  if (i < table_end) return "section table";
  for (const FblSection& s : f.sections())
    if (i >= s.offset && i < s.offset + s.bytes) return "section '" + s.name + "'";
  return "padding";
}

TEST(FblFile, flippedBitAnywhereIsReportedWithThePartItHit) {
  TempDir dir;
  const std::string good = dir.file("good.fbl");
  writeSample(good, Sample());
  const std::string bytes = test::readBytes(good);
  const FblFile reference = FblFile::open(good);
  const std::string path = dir.file("flipped.fbl");
  size_t tried = 0;
  for (size_t i = 0; i < bytes.size(); i += (i < 400 ? 1 : 3)) {
    std::string b = bytes;
    b[i] = static_cast<char>(b[i] ^ (1 << (i % 8)));
    test::writeBytes(path, b);
    const std::string message = errorOf(path);
    const std::string part = partAt(reference, i);
    ASSERT_FALSE(message.empty()) << "flip at byte " << i << " (" << part << ") was not detected";
    EXPECT_EQ(message.rfind(path, 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find(part), std::string::npos) << "byte " << i << ": expected '" << part << "' in: " << message;
    ++tried;
  }
  EXPECT_GT(tried, 500u);
}

TEST(FblFile, everyTruncatedPrefixIsReported) {
  TempDir dir;
  const std::string good = dir.file("good.fbl");
  writeSample(good, Sample());
  const std::string bytes = test::readBytes(good);
  const FblFile reference = FblFile::open(good);
  const std::string path = dir.file("cut.fbl");
  for (size_t n = 0; n < bytes.size(); ++n) {
    test::writeBytes(path, bytes.substr(0, n));
    const std::string message = errorOf(path);
    ASSERT_FALSE(message.empty()) << "prefix of " << n << " bytes was accepted";
    EXPECT_EQ(message.rfind(path, 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    if (n < 8) {
      EXPECT_NE(message.find("not a .fbl file"), std::string::npos) << message;
      continue;
    }
    EXPECT_NE(message.find("truncated"), std::string::npos) << n << ": " << message;
    // The first section cut short is named.
    for (const FblSection& s : reference.sections()) {
      if (n >= fbl::kHeaderBytes + 8 * fbl::kSectionEntryBytes && s.offset + s.bytes > n) {
        EXPECT_NE(message.find("section '" + s.name + "' ends at byte " + std::to_string(s.offset + s.bytes)),
                  std::string::npos)
            << n << ": " << message;
        break;
      }
    }
  }
}

TEST(FblFile, badMagicSaysNotAFblFile) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  std::string b = test::readBytes(path);
  std::memcpy(b.data(), "TRACK\0\0\0", 8);
  test::writeBytes(path, b);
  const std::string message = errorOf(path);
  EXPECT_NE(message.find("not a .fbl file (magic \"TRACK\\x00\\x00\\x00\""), std::string::npos) << message;
}

TEST(FblFile, newerVersionIsReportedAsNewerNotCorrupt) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  std::string b = test::readBytes(path);
  storeUnaligned<uint32_t>(b.data() + fbl::header::kVersion, 7);
  fixChecksums(b);
  test::writeBytes(path, b);
  EXPECT_EQ(errorOf(path), path + ": .fbl version 7 is newer than this fibscope (1)");
  // The same field changed without a matching checksum is corruption.
  b = test::readBytes(path);
  storeUnaligned<uint32_t>(b.data() + fbl::header::kVersion, 1);
  test::writeBytes(path, b);
  const std::string message = errorOf(path);
  EXPECT_NE(message.find("header (byte 0): checksum mismatch"), std::string::npos) << message;
}

TEST(FblFile, overlappingSectionIsRejected) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  std::string b = test::readBytes(path);
  const uint64_t first_offset = loadUnaligned<uint64_t>(entryAt(b, 0) + fbl::entry::kOffset);
  storeUnaligned<uint64_t>(entryAt(b, 1) + fbl::entry::kOffset, first_offset + 64);
  fixChecksums(b);
  test::writeBytes(path, b);
  const std::string message = errorOf(path);
  EXPECT_NE(message.find("section table entry 1 ('fiber_first_fiblet'): starts at byte " +
                         std::to_string(first_offset + 64) + ", inside section 'fiblets'"),
            std::string::npos)
      << message;
}

TEST(FblFile, misalignedSectionIsRejected) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  std::string b = test::readBytes(path);
  const uint64_t offset = loadUnaligned<uint64_t>(entryAt(b, 2) + fbl::entry::kOffset);
  storeUnaligned<uint64_t>(entryAt(b, 2) + fbl::entry::kOffset, offset + 4);
  fixChecksums(b);
  test::writeBytes(path, b);
  const std::string message = errorOf(path);
  EXPECT_NE(message.find("('fiber_length_mm'): starts at byte " + std::to_string(offset + 4) + ", expected " +
                         std::to_string(offset)),
            std::string::npos)
      << message;
}

TEST(FblFile, sectionPastTheEndIsRejectedWithoutOverflow) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  const std::string good = test::readBytes(path);
  // A last section claiming 2^60 bytes, then one whose offset + bytes wraps.
  for (const uint64_t bytes : {uint64_t(1) << 60, ~uint64_t(0) - 63}) {
    std::string b = good;
    uint8_t* e = entryAt(b, 5);  // "source", utf8: element count == bytes
    storeUnaligned<uint64_t>(e + fbl::entry::kElementCount, bytes);
    storeUnaligned<uint64_t>(e + fbl::entry::kBytes, bytes);
    fixChecksums(b);
    test::writeBytes(path, b);
    const std::string message = errorOf(path);
    EXPECT_NE(message.find("('source'): bytes"), std::string::npos) << message;
    EXPECT_NE(message.find("run past the end of the file"), std::string::npos) << message;
  }
  // Element count that disagrees with the byte size.
  std::string b = good;
  storeUnaligned<uint64_t>(entryAt(b, 4) + fbl::entry::kElementCount, 4);
  fixChecksums(b);
  test::writeBytes(path, b);
  EXPECT_NE(errorOf(path).find("4 elements of 3 x float32 do not make 36 bytes"), std::string::npos) << errorOf(path);
}

TEST(FblFile, headerCountsMustAgreeWithStandardSections) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  FblHeaderFields fields = sampleFields();
  fields.fiber_count = 4;  // fiber_length_mm below has 3
  {
    FblWriter w(path, fields, true);
    const float length[3] = {1, 2, 3};
    w.writeSection({std::string(kFblSectionFiberLength), FblDType::kFloat32, 1}, length, sizeof length);
    w.finish();
  }
  EXPECT_NE(errorOf(path).find("section 'fiber_length_mm' (byte 6400): 3 elements, expected 4 (one per fiber)"),
            std::string::npos)
      << errorOf(path);
}

TEST(FblFile, trailingBytesAreRejected) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  writeSample(path, Sample());
  test::writeBytes(path, test::readBytes(path) + std::string(64, '\0'));
  EXPECT_NE(errorOf(path).find("64 unexpected bytes after the end"), std::string::npos) << errorOf(path);
}

TEST(FblFile, writerRefusesToOverwrite) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  test::writeBytes(path, "keep me");
  try {
    FblWriter w(path, sampleFields(), /*overwrite=*/false);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("exists"), std::string::npos) << e.what();
  }
  EXPECT_EQ(test::readBytes(path), "keep me");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(FblFile, abandonedOrFailedWriteLeavesNoFile) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  {
    FblWriter w(path, sampleFields(), true);
    const uint32_t words[4] = {1, 2, 3, 4};
    w.writeSection({"fiblets", FblDType::kUint32, 1}, words, sizeof words);
  }  // no finish()
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  try {
    FblWriter w(path, sampleFields(), true);
    w.beginSection("fiber_length_mm", FblDType::kFloat32);
    const uint8_t three[3] = {1, 2, 3};
    w.append(three, 3);
    w.endSection();  // 3 bytes is not a float32
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("3 bytes is not a whole number of 1 x float32 elements"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(FblFile, writerRejectsBadSectionNamesAndTooManySections) {
  TempDir dir;
  FblWriter w(dir.file("a.fbl"), sampleFields(), true, 2);
  EXPECT_THROW(w.beginSection("", FblDType::kUint8), Error);
  EXPECT_THROW(w.beginSection(std::string(48, 'x'), FblDType::kUint8), Error);
  EXPECT_THROW(w.beginSection("line\nbreak", FblDType::kUint8), Error);
  EXPECT_THROW(w.beginSection("zero", FblDType::kUint8, 0), Error);
  EXPECT_THROW(w.beginSection("odd", static_cast<FblDType>(99)), Error);
  w.writeSection({std::string(47, 'x'), FblDType::kUint8, 1}, nullptr, 0);
  EXPECT_THROW(w.beginSection(std::string(47, 'x'), FblDType::kUint8), Error);
  w.writeSection({"b", FblDType::kUint8, 1}, "z", 1);
  EXPECT_THROW(w.beginSection("c", FblDType::kUint8), Error);
  w.finish();
  const FblFile f = FblFile::open(dir.file("a.fbl"));
  EXPECT_EQ(f.sections().size(), 2u);
  EXPECT_EQ(f.sections()[0].name, std::string(47, 'x'));
}

TEST(FblFile, countsSetAfterStreamingReachTheHeader) {
  TempDir dir;
  const std::string path = dir.file("a.fbl");
  FblWriter w(path, FblHeaderFields{}, true);
  w.fields().fiblet_record_bytes = 8;
  w.beginSection("fiblets", FblDType::kUint32);
  for (uint32_t i = 0; i < 1000; ++i) w.append(&i, 4);
  w.endSection();
  w.fields().fiblet_count = 500;
  w.finish();
  const FblFile f = FblFile::open(path);
  EXPECT_EQ(f.header().fiblet_count, 500u);
  EXPECT_EQ(f.array<uint32_t>(*f.find("fiblets"))[999], 999u);
}

}  // namespace
}  // namespace fibscope
