// The viewer's cache of compressed copies: keys, hits, staleness, damaged
// entries, fallbacks and eviction.
#include "codec/fbl_cache.h"

#include <fcntl.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "codec/fbl_codec.h"
#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::TempDir;

// A phantom .tck of a few MB, so that most of it lies outside the sampled blocks.
std::string writePhantomTck(const TempDir& dir, const std::string& name, uint64_t streamlines = 300) {
  return test::writePhantomTck(dir, name, streamlines, 3);
}

struct stat statOf(const std::string& path) {
  struct stat st {};
  EXPECT_EQ(::stat(path.c_str(), &st), 0) << path;
  return st;
}

void restoreTimes(const std::string& path, const struct stat& st) {
  const struct timespec times[2] = {st.st_atim, st.st_mtim};
  ASSERT_EQ(::utimensat(AT_FDCWD, path.c_str(), times, 0), 0) << path;
}

// Flips one byte in place, keeping size and times.
void flipByte(const std::string& path, uint64_t offset) {
  const struct stat before = statOf(path);
  std::string bytes = test::readBytes(path);
  ASSERT_LT(offset, bytes.size());
  bytes[offset] = char(bytes[offset] ^ 0x5a);
  test::writeBytes(path, bytes);
  restoreTimes(path, before);
}

bool inSampledBlock(uint64_t size, uint64_t offset) {
  for (const auto& [begin, bytes] : fblCacheSampledRanges(size))
    if (offset >= begin && offset < begin + bytes) return true;
  return false;
}

TEST(FblCache, sampledRangesCoverFirstAndLastBlockAndWholeSmallFiles) {
  const uint64_t size = 100'000'000;
  const auto ranges = fblCacheSampledRanges(size);
  ASSERT_EQ(ranges.size(), kFblCacheSampleBlocks);
  EXPECT_EQ(ranges.front().first, 0u);
  EXPECT_EQ(ranges.back().first + ranges.back().second, size);
  for (size_t i = 1; i < ranges.size(); ++i) EXPECT_GE(ranges[i].first, ranges[i - 1].first + ranges[i - 1].second);
  // A small file is hashed whole.
  uint64_t covered = 0;
  for (const auto& r : fblCacheSampledRanges(300'000)) covered += r.second;
  EXPECT_EQ(covered, 300'000u);
  EXPECT_TRUE(fblCacheSampledRanges(0).empty());
}

TEST(FblCache, secondLookupOfTheSameFileHits) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck");
  FblCache cache(dir.file("cache"));
  EXPECT_FALSE(cache.lookup(tck).has_value());
  FblCacheEntry first = cache.getFile(tck);
  EXPECT_FALSE(first.from_cache);
  EXPECT_FALSE(first.temporary);
  EXPECT_GT(first.report.points, 0u);
  const std::optional<std::string> hit = cache.lookup(tck);
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(*hit, first.path);
  FblCacheEntry second = cache.getFile(tck);
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(second.file.header().point_count, first.file.header().point_count);
  // Through a relative spelling of the same file too (the key is canonical).
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir.path());
  const bool relative_hit = cache.lookup("./a.tck").has_value();
  std::filesystem::current_path(cwd);
  EXPECT_TRUE(relative_hit);
}

TEST(FblCache, aChangedByteInASampledBlockIsAMissEvenWithSameSizeAndMtime) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck");
  const uint64_t size = std::filesystem::file_size(tck);
  ASSERT_GT(size, kFblCacheSampleBlocks * kFblCacheSampleBlockBytes) << "the file must be larger than the sample";
  FblCache cache(dir.file("cache"));
  cache.getFile(tck);
  ASSERT_TRUE(cache.lookup(tck).has_value());
  // The middle of the 8th block: well inside the point data.
  const auto ranges = fblCacheSampledRanges(size);
  const uint64_t offset = ranges[8].first + ranges[8].second / 2;
  ASSERT_TRUE(inSampledBlock(size, offset));
  flipByte(tck, offset);
  EXPECT_FALSE(cache.lookup(tck).has_value());
  // Restoring the byte makes the entry valid again (same key).
  flipByte(tck, offset);
  EXPECT_TRUE(cache.lookup(tck).has_value());
}

TEST(FblCache, aChangedByteOutsideTheSampleGoesUnseenByDesign) {
  // The documented trade-off: 1 MiB is hashed, not the whole file; an edit
  // that keeps size and mtime and misses every sampled block is not seen.
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck");
  const uint64_t size = std::filesystem::file_size(tck);
  FblCache cache(dir.file("cache"));
  cache.getFile(tck);
  const auto ranges = fblCacheSampledRanges(size);
  const uint64_t offset = ranges[8].first + ranges[8].second + 100;
  ASSERT_LT(offset, ranges[9].first);
  ASSERT_FALSE(inSampledBlock(size, offset));
  flipByte(tck, offset);
  EXPECT_TRUE(cache.lookup(tck).has_value());
}

TEST(FblCache, aChangedMtimeAloneIsAMiss) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck");
  FblCache cache(dir.file("cache"));
  cache.getFile(tck);
  struct stat st = statOf(tck);
  st.st_mtim.tv_nsec = (st.st_mtim.tv_nsec + 1) % 1000000000;  // 1 ns later (or earlier)
  restoreTimes(tck, st);
  EXPECT_FALSE(cache.lookup(tck).has_value());
}

TEST(FblCache, aChangedSizeIsAMissAndTheOldVersionIsDropped) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck");
  FblCache cache(dir.file("cache"));
  const std::string old_entry = cache.getFile(tck).path;
  const struct stat before = statOf(tck);
  test::writeBytes(tck, test::readBytes(tck) + "appended");
  restoreTimes(tck, before);  // same mtime: the size alone must tell
  EXPECT_FALSE(cache.lookup(tck).has_value());
  std::filesystem::resize_file(tck, before.st_size);
  restoreTimes(tck, before);
  ASSERT_TRUE(cache.lookup(tck).has_value());
  // A new version of the file: rebuilt, and the old version's entry is gone.
  writePhantomTck(dir, "b.tck", 60);
  std::filesystem::rename(dir.file("b.tck"), tck);
  const FblCacheEntry rebuilt = cache.getFile(tck);
  EXPECT_FALSE(rebuilt.from_cache);
  EXPECT_EQ(rebuilt.file.header().fiber_count, 60u);
  EXPECT_NE(rebuilt.path, old_entry);
  EXPECT_FALSE(std::filesystem::exists(old_entry));
}

TEST(FblCache, aCorruptedEntryIsDeletedWithAWarningAndRebuilt) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck");
  FblCache cache(dir.file("cache"));
  const FblCacheEntry first = cache.getFile(tck);
  const std::string entry = first.path;
  const uint64_t fbl_bytes = first.file.fileBytes();
  // A byte inside the fiblets section: only the checksum can tell.
  const FblSection* fiblets = first.file.find(kFblSectionFiblets);
  ASSERT_NE(fiblets, nullptr);
  const uint64_t offset = fiblets->offset + fiblets->bytes / 2;
  ASSERT_LT(offset, fbl_bytes);
  {
    std::string bytes = test::readBytes(entry);
    bytes[offset] = char(bytes[offset] ^ 1);
    test::writeBytes(entry, bytes);
  }
  const FblCacheKey key = fblCacheKeyForFile(tck);
  std::vector<std::string> warnings;
  EXPECT_FALSE(cache.lookup(key, &warnings).has_value());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("rebuilt"), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[0].find('\n'), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(entry));

  // Damaged again, now through get(): rebuilt in place, with the warning.
  cache.getFile(tck);
  std::filesystem::resize_file(entry, fbl_bytes / 2);  // truncated
  const FblCacheEntry rebuilt = cache.getFile(tck);
  EXPECT_FALSE(rebuilt.from_cache);
  EXPECT_EQ(rebuilt.file.fileBytes(), fbl_bytes);
  bool warned = false;
  for (const std::string& w : rebuilt.warnings) warned = warned || w.find("rebuilt") != std::string::npos;
  EXPECT_TRUE(warned);
  EXPECT_TRUE(cache.getFile(tck).from_cache);
}

TEST(FblCache, aDifferentCodecVersionOrOptionsIsAMiss) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck", 50);
  FblCache cache(dir.file("cache"));
  cache.getFile(tck);
  FblCacheKey key = fblCacheKeyForFile(tck);
  ASSERT_TRUE(cache.lookup(key).has_value());
  FblCacheKey newer = key;
  newer.codec_version = kFibletCodecVersion + 1;
  EXPECT_NE(newer.digest(), key.digest());
  EXPECT_FALSE(cache.lookup(newer).has_value());
  CompressOptions other;
  other.params.points_per_fiblet = 32;
  EXPECT_FALSE(cache.lookup(tck, other).has_value());
  // The thread count does not change the output, so it is not in the key.
  CompressOptions threads;
  threads.threads = 1;
  EXPECT_TRUE(cache.lookup(tck, threads).has_value());
}

TEST(FblCache, aSidecarOfAnotherKeyUnderTheSameNameIsNeverServed) {
  // What a digest collision would look like: the name matches, a field does not.
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "a.tck", 50);
  FblCache cache(dir.file("cache"));
  cache.getFile(tck);
  const FblCacheKey key = fblCacheKeyForFile(tck);
  FblCacheKey other = key;
  other.sample_crc ^= 1;
  std::string sidecar = test::readBytes(cache.sidecarPath(key));
  const std::string needle = "\"sample_crc\": " + std::to_string(key.sample_crc);
  const size_t at = sidecar.find(needle);
  ASSERT_NE(at, std::string::npos) << sidecar;
  sidecar.replace(at, needle.size(), "\"sample_crc\": " + std::to_string(other.sample_crc));
  test::writeBytes(cache.sidecarPath(key), sidecar);
  EXPECT_FALSE(cache.lookup(key).has_value());
}

TEST(FblCache, phantomKeysDifferByCountSeedAndVersionAndHit) {
  PhantomOptions a;
  a.streamlines = 40;
  PhantomOptions b = a;
  b.streamlines = 41;
  PhantomOptions c = a;
  c.seed = 2;
  PhantomOptions d = a;
  d.threads = 1;  // not part of the output
  const FblCacheKey ka = fblCacheKeyForPhantom(a), kb = fblCacheKeyForPhantom(b), kc = fblCacheKeyForPhantom(c);
  EXPECT_NE(ka.digest(), kb.digest());
  EXPECT_NE(ka.digest(), kc.digest());
  EXPECT_FALSE(ka == kb);
  EXPECT_FALSE(ka == kc);
  EXPECT_TRUE(ka == fblCacheKeyForPhantom(d));
  EXPECT_EQ(ka.phantom_version, kPhantomGeneratorVersion);

  TempDir dir;
  FblCache cache(dir.file("cache"));
  EXPECT_FALSE(cache.getPhantom(a).from_cache);
  EXPECT_TRUE(cache.getPhantom(a).from_cache);
  EXPECT_FALSE(cache.getPhantom(c).from_cache);
}

TEST(FblCache, anUnwritableDirectoryFallsBackToATemporaryCopyAndWarnsOnce) {
  TempDir dir;
  test::writeBytes(dir.file("plain-file"), "x");
  FblCache cache(dir.file("plain-file/cache"));  // cannot be created
  PhantomOptions phantom;
  phantom.streamlines = 20;
  const FblCacheEntry first = cache.getPhantom(phantom);
  EXPECT_TRUE(first.temporary);
  EXPECT_FALSE(first.from_cache);
  EXPECT_TRUE(first.path.empty());
  EXPECT_EQ(first.file.header().fiber_count, 20u);
  ASSERT_EQ(first.warnings.size(), 1u);
  EXPECT_NE(first.warnings[0].find("temporary"), std::string::npos) << first.warnings[0];
  const FblCacheEntry second = cache.getPhantom(phantom);
  EXPECT_TRUE(second.temporary);
  EXPECT_TRUE(second.warnings.empty());
  // The temporary file is unlinked, the map still reads.
  EXPECT_NO_THROW(second.file.verify());
}

TEST(FblCache, evictionDropsTheLeastRecentlyUsedEntriesDownToTheCap) {
  TempDir dir;
  FblCache big(dir.file("cache"), uint64_t(1) << 40);
  PhantomOptions a, b, c;
  a.streamlines = b.streamlines = c.streamlines = 30;
  b.seed = 2;
  c.seed = 3;
  const FblCacheEntry ea = big.getPhantom(a);
  const FblCacheEntry eb = big.getPhantom(b);
  // a is older than b; then a is used again: b is now the least recent.
  const struct timespec old_times[2] = {{1000, 0}, {1000, 0}};
  const struct timespec older_times[2] = {{500, 0}, {500, 0}};
  ASSERT_EQ(::utimensat(AT_FDCWD, ea.path.c_str(), old_times, 0), 0);
  ASSERT_EQ(::utimensat(AT_FDCWD, eb.path.c_str(), older_times, 0), 0);
  ASSERT_TRUE(big.getPhantom(a).from_cache);  // refreshes a's mtime
  // A cap that holds two entries: storing c evicts b.
  const uint64_t cap = ea.file.fileBytes() + eb.file.fileBytes() + 1000;
  FblCache small(dir.file("cache"), cap);
  const FblCacheEntry ec = small.getPhantom(c);
  EXPECT_FALSE(std::filesystem::exists(eb.path));
  EXPECT_FALSE(std::filesystem::exists(small.sidecarPath(fblCacheKeyForPhantom(b))));
  EXPECT_TRUE(std::filesystem::exists(ea.path));
  EXPECT_TRUE(std::filesystem::exists(ec.path));
}

TEST(FblCache, directoryComesFromTheEnvironment) {
  const char* saved_dir = std::getenv("FIBSCOPE_CACHE_DIR");
  const char* saved_xdg = std::getenv("XDG_CACHE_HOME");
  const std::string keep_dir = saved_dir ? saved_dir : "", keep_xdg = saved_xdg ? saved_xdg : "";
  ::setenv("FIBSCOPE_CACHE_DIR", "/some/where", 1);
  EXPECT_EQ(defaultFblCacheDir(), "/some/where");
  ::unsetenv("FIBSCOPE_CACHE_DIR");
  ::setenv("XDG_CACHE_HOME", "/xdg", 1);
  EXPECT_EQ(defaultFblCacheDir(), "/xdg/fibscope");
  ::unsetenv("XDG_CACHE_HOME");
  if (const char* home = std::getenv("HOME"); home && *home) {
    EXPECT_EQ(defaultFblCacheDir(), std::string(home) + "/.cache/fibscope");
  }
  ::setenv("FIBSCOPE_CACHE_MAX_BYTES", "12345", 1);
  EXPECT_EQ(defaultFblCacheMaxBytes(), 12345u);
  ::setenv("FIBSCOPE_CACHE_MAX_BYTES", "lots", 1);
  EXPECT_EQ(defaultFblCacheMaxBytes(), kFblCacheDefaultMaxBytes);
  ::unsetenv("FIBSCOPE_CACHE_MAX_BYTES");
  if (saved_dir) ::setenv("FIBSCOPE_CACHE_DIR", keep_dir.c_str(), 1);
  if (saved_xdg) ::setenv("XDG_CACHE_HOME", keep_xdg.c_str(), 1);
}

TEST(FblCache, aMissingInputIsAnErrorNamingIt) {
  TempDir dir;
  FblCache cache(dir.file("cache"));
  const std::string missing = dir.file("missing.tck");
  try {
    cache.getFile(missing);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fibscope
