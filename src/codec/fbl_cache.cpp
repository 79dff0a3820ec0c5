#include "codec/fbl_cache.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <atomic>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "codec/fbl_codec.h"
#include "codec/fbl_format.h"
#include "core/checksum.h"
#include "core/error.h"
#include "core/output_file.h"

namespace fibscope {
namespace fs = std::filesystem;
namespace {

std::string hex64(uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016" PRIx64, v);
  return text;
}

// Exact text of a double (17 significant digits round-trip).
std::string exact(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", v);
  return text;
}

int64_t mtimeNs(const struct stat& st) { return int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec; }

// CRC-32C of the sampled blocks of a regular file, read with pread.
uint32_t sampledCrc(const std::string& path, uint64_t size) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) failErrno(path, "cannot open for reading");
  std::vector<uint8_t> block(kFblCacheSampleBlockBytes);
  uint32_t crc = 0;
  try {
    for (const auto& [offset, bytes] : fblCacheSampledRanges(size)) {
      uint64_t got = 0;
      while (got < bytes) {
        const ssize_t n = ::pread(fd, block.data() + got, size_t(bytes - got), off_t(offset + got));
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) failErrno(path, "cannot read byte " + std::to_string(offset + got));
        // The file shrank since stat: hash what is there; the size in the
        // key no longer matches the file, so the next lookup misses.
        if (n == 0) break;
        got += uint64_t(n);
      }
      crc = crc32c(block.data(), size_t(got), crc);
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return crc;
}

// Removes a file, ignoring a missing one.
void removeQuietly(const std::string& path) {
  std::error_code ec;
  fs::remove(path, ec);
}

nlohmann::json keyToJson(const FblCacheKey& k) {
  nlohmann::json j;
  j["key_version"] = k.key_version;
  j["kind"] = k.kind;
  j["path"] = k.path;
  j["size"] = k.size;
  j["mtime_ns"] = k.mtime_ns;
  j["sample_crc"] = k.sample_crc;
  j["phantom"] = k.phantom;
  j["phantom_version"] = k.phantom_version;
  j["format_version"] = k.format_version;
  j["codec_version"] = k.codec_version;
  j["options"] = k.options;
  return j;
}

// Throws nlohmann's exceptions on missing fields or wrong types.
FblCacheKey keyFromJson(const nlohmann::json& j) {
  FblCacheKey k;
  k.key_version = j.at("key_version").get<uint32_t>();
  k.kind = j.at("kind").get<std::string>();
  k.path = j.at("path").get<std::string>();
  k.size = j.at("size").get<uint64_t>();
  k.mtime_ns = j.at("mtime_ns").get<int64_t>();
  k.sample_crc = j.at("sample_crc").get<uint32_t>();
  k.phantom = j.at("phantom").get<std::string>();
  k.phantom_version = j.at("phantom_version").get<uint32_t>();
  k.format_version = j.at("format_version").get<uint32_t>();
  k.codec_version = j.at("codec_version").get<uint32_t>();
  k.options = j.at("options").get<std::string>();
  return k;
}

struct Sidecar {
  FblCacheKey key;
  uint64_t fbl_bytes = 0;
};

// nullopt when the sidecar is missing; throws Error when it is unreadable
// or malformed.
std::optional<Sidecar> readSidecar(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  std::string text;
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) failErrno(path, "cannot open cache sidecar");
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) {
      text.append(buffer, n);
      if (text.size() > (size_t(1) << 20)) {
        std::fclose(f);
        fail(path, "cache sidecar larger than 1 MiB");
      }
    }
    std::fclose(f);
  }
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    Sidecar s;
    s.key = keyFromJson(j.at("key"));
    s.fbl_bytes = j.at("fbl_bytes").get<uint64_t>();
    return s;
  } catch (const nlohmann::json::exception& e) {
    fail(path, std::string("malformed cache sidecar: ") + e.what());
  }
}

void writeSidecar(const std::string& path, const FblCacheKey& key, uint64_t fbl_bytes) {
  nlohmann::json j;
  j["key"] = keyToJson(key);
  j["fbl_bytes"] = fbl_bytes;
  OutputFile out(path, /*overwrite=*/true);
  out.write(j.dump(1) + "\n");
  out.commit();
}

// Opens and fully checks a .fbl: container, every checksum, codec header.
FblFile openVerified(const std::string& path) {
  FblFile file = FblFile::open(path);
  file.verify();
  codecParamsFromFbl(file.header(), path);
  if (!file.find(kFblSectionFiblets) || !file.find(kFblSectionFiberFirstFiblet))
    fail(path, "missing the fiblets or fiber_first_fiblet section");
  return file;
}

bool directoryWritable(const std::string& dir, std::string& why) {
  if (dir.empty()) {
    why = "no cache directory ($FIBSCOPE_CACHE_DIR, $XDG_CACHE_HOME and $HOME are unset)";
    return false;
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    why = dir + ": cannot create the cache directory: " + ec.message();
    return false;
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    why = dir + ": cache directory not writable: " + std::strerror(errno);
    return false;
  }
  return true;
}

std::atomic<uint64_t> temporary_counter{0};

}  // namespace

std::string FblCacheKey::json() const { return keyToJson(*this).dump(); }

std::string FblCacheKey::digest() const {
  // FNV-1a, 64 bit: only names the entry; the sidecar is compared field by
  // field, so a collision costs a recompression, never a wrong file.
  uint64_t h = 0xcbf29ce484222325ull;
  for (const unsigned char c : json()) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return hex64(h);
}

std::vector<std::pair<uint64_t, uint64_t>> fblCacheSampledRanges(uint64_t size) {
  std::vector<std::pair<uint64_t, uint64_t>> ranges;
  const uint64_t block = kFblCacheSampleBlockBytes;
  const uint64_t blocks = kFblCacheSampleBlocks;
  if (size <= block * blocks) {
    // Small file: every byte, in blocks.
    for (uint64_t offset = 0; offset < size; offset += block) ranges.emplace_back(offset, std::min(block, size - offset));
    return ranges;
  }
  // Offsets i * (size - block) / (blocks - 1): block 0 at the start, the
  // last one ending at the end of the file, no overlap (size > blocks * block).
  const uint64_t span = size - block;
  for (uint64_t i = 0; i < blocks; ++i) {
    // span * i / (blocks - 1) without overflowing 64 bits.
    const uint64_t offset = span / (blocks - 1) * i + span % (blocks - 1) * i / (blocks - 1);
    ranges.emplace_back(offset, block);
  }
  return ranges;
}

std::string fblCacheOptionsText(const CompressOptions& o) {
  std::string s;
  s += "mode=" + std::to_string(int(o.encode.mode));
  s += " search=" + std::to_string(o.encode.search_size);
  s += " step_tolerance=" + exact(o.encode.step_tolerance);
  s += " max_point_error=" + exact(o.encode.max_point_error);
  s += " n=" + std::to_string(o.params.points_per_fiblet);
  s += " delta_mm=" + exact(o.params.delta_mm);
  s += " alpha_deg=" + exact(o.params.alpha_deg);
  s += " alpha_percentile=" + exact(o.params.alpha_percentile);
  s += " alpha_margin=" + exact(o.params.alpha_margin);
  s += " min_alpha_deg=" + exact(o.params.min_alpha_deg);
  s += " max_alpha_deg=" + exact(o.params.max_alpha_deg);
  s += " max_samples=" + std::to_string(o.params.max_samples);
  s += " resample=" + std::to_string(int(o.resample));
  return s;
}

FblCacheKey fblCacheKeyForFile(const std::string& path, const CompressOptions& options) {
  FblCacheKey key;
  key.kind = "file";
  key.format_version = fbl::kFormatVersion;
  key.codec_version = kFibletCodecVersion;
  key.options = fblCacheOptionsText(options);
  std::error_code ec;
  const fs::path canonical = fs::canonical(path, ec);
  if (ec) fail(path, "cannot open: " + ec.message());
  key.path = canonical.string();
  struct stat st {};
  if (::stat(key.path.c_str(), &st) != 0) failErrno(path, "cannot stat");
  if (S_ISREG(st.st_mode)) {
    key.size = uint64_t(st.st_size);
    key.mtime_ns = mtimeNs(st);
    key.sample_crc = sampledCrc(key.path, key.size);
    return key;
  }
  if (!S_ISDIR(st.st_mode)) fail(path, "not a regular file or directory");
  // A TRX directory: every member's relative name, size and mtime go into
  // the hash (a member rewritten in place changes its mtime), plus the
  // sampled bytes of each member.
  std::vector<fs::path> members;
  for (fs::recursive_directory_iterator it(canonical, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec)) members.push_back(it->path());
  if (ec) fail(path, "cannot list the directory: " + ec.message());
  std::sort(members.begin(), members.end());
  uint32_t crc = 0;
  for (const fs::path& member : members) {
    struct stat ms {};
    if (::stat(member.c_str(), &ms) != 0) failErrno(member.string(), "cannot stat");
    const std::string rel = fs::relative(member, canonical).string();
    crc = crc32c(rel.data(), rel.size() + 1, crc);  // with the terminator: names stay separated
    const uint64_t size = uint64_t(ms.st_size);
    const int64_t mtime = mtimeNs(ms);
    crc = crc32c(&size, sizeof size, crc);
    crc = crc32c(&mtime, sizeof mtime, crc);
    const uint32_t member_crc = sampledCrc(member.string(), size);
    crc = crc32c(&member_crc, sizeof member_crc, crc);
    key.size += size;
    key.mtime_ns = std::max(key.mtime_ns, mtime);
  }
  key.sample_crc = crc;
  return key;
}

FblCacheKey fblCacheKeyForPhantom(const PhantomOptions& p, const CompressOptions& options) {
  FblCacheKey key;
  key.kind = "phantom";
  key.format_version = fbl::kFormatVersion;
  key.codec_version = kFibletCodecVersion;
  key.options = fblCacheOptionsText(options);
  key.phantom_version = kPhantomGeneratorVersion;
  // Every option that changes the streamlines (not the thread count).
  std::string s = "streamlines=" + std::to_string(p.streamlines) + " seed=" + std::to_string(p.seed) +
                  " step_mm=" + exact(p.step_mm) + " max_angle_deg=" + exact(p.max_angle_deg) +
                  " min_length_mm=" + exact(p.min_length_mm) + " max_length_mm=" + exact(p.max_length_mm) +
                  " jitter=" + exact(p.jitter) + " weights=";
  for (size_t i = 0; i < p.bundle_weights.size(); ++i) {
    if (i) s += ',';
    s += exact(p.bundle_weights[i]);
  }
  key.phantom = s;
  return key;
}

std::string defaultFblCacheDir() {
  auto env = [](const char* name) -> std::string {
    const char* v = std::getenv(name);
    return v && *v ? v : "";
  };
  if (std::string d = env("FIBSCOPE_CACHE_DIR"); !d.empty()) return d;
  if (std::string d = env("XDG_CACHE_HOME"); !d.empty()) return d + "/fibscope";
  if (std::string d = env("HOME"); !d.empty()) return d + "/.cache/fibscope";
  return "";
}

uint64_t defaultFblCacheMaxBytes() {
  const char* v = std::getenv("FIBSCOPE_CACHE_MAX_BYTES");
  if (v && *v) {
    char* end = nullptr;
    errno = 0;
    const unsigned long long n = std::strtoull(v, &end, 10);
    if (errno == 0 && end && *end == '\0' && n > 0) return uint64_t(n);
  }
  return kFblCacheDefaultMaxBytes;
}

FblCache::FblCache(std::string dir, uint64_t max_bytes)
    : dir_(dir.empty() ? defaultFblCacheDir() : std::move(dir)),
      max_bytes_(max_bytes ? max_bytes : defaultFblCacheMaxBytes()) {}

std::string FblCache::fblPath(const FblCacheKey& key) const { return dir_ + "/" + key.digest() + ".fbl"; }
std::string FblCache::sidecarPath(const FblCacheKey& key) const { return dir_ + "/" + key.digest() + ".json"; }

std::optional<FblFile> FblCache::openEntry(const FblCacheKey& key, std::vector<std::string>* warnings) {
  if (dir_.empty()) return std::nullopt;
  const std::string fbl_path = fblPath(key), sidecar_path = sidecarPath(key);
  std::error_code ec;
  if (!fs::exists(fbl_path, ec)) return std::nullopt;
  auto discard = [&](const std::string& why) {
    if (warnings) warnings->push_back(fbl_path + ": cached copy of " + (key.path.empty() ? key.kind : key.path) +
                                      " discarded and rebuilt: " + why);
    removeQuietly(fbl_path);
    removeQuietly(sidecar_path);
  };
  std::optional<Sidecar> sidecar;
  try {
    sidecar = readSidecar(sidecar_path);
  } catch (const Error& e) {
    discard(e.what());
    return std::nullopt;
  }
  // No sidecar: another viewer is between its two renames, or a crash
  // came between them. A miss; the rebuild writes both.
  if (!sidecar) return std::nullopt;
  // Another key under the same digest (a collision or a stale format of
  // sidecar): a miss; the store overwrites it.
  if (!(sidecar->key == key)) return std::nullopt;
  try {
    FblFile file = openVerified(fbl_path);
    if (file.fileBytes() != sidecar->fbl_bytes)
      fail(fbl_path, "size " + std::to_string(file.fileBytes()) + " bytes, the sidecar recorded " +
                         std::to_string(sidecar->fbl_bytes));
    // Refresh the mtime: eviction drops the least recently used entries
    // first (atime is unreliable under relatime/noatime).
    ::utimensat(AT_FDCWD, fbl_path.c_str(), nullptr, 0);
    return file;
  } catch (const Error& e) {
    discard(e.what());
  } catch (const std::bad_alloc&) {
    discard("out of memory while verifying");
  }
  return std::nullopt;
}

std::optional<std::string> FblCache::lookup(const FblCacheKey& key, std::vector<std::string>* warnings) {
  if (openEntry(key, warnings)) return fblPath(key);
  return std::nullopt;
}

std::optional<std::string> FblCache::lookup(const std::string& input, const CompressOptions& options) {
  return lookup(fblCacheKeyForFile(input, options));
}

FblCacheEntry FblCache::compressTemporary(const ReaderFactory& open_input, const CompressOptions& options,
                                          const std::string& reason, std::vector<std::string> warnings) {
  FblCacheEntry entry;
  entry.warnings = std::move(warnings);
  if (!warned_unwritable_) {
    warned_unwritable_ = true;
    entry.warnings.push_back(reason + "; compressed copies go to temporary files instead");
  }
  std::error_code ec;
  fs::path tmp = fs::temp_directory_path(ec);
  if (ec) tmp = "/tmp";
  const std::string path = (tmp / ("fibscope-" + std::to_string(::getpid()) + "-" +
                                   std::to_string(temporary_counter.fetch_add(1)) + ".fbl"))
                               .string();
  CompressOptions o = options;
  o.overwrite = true;
  entry.report = compressTractogram(open_input, path, o);
  try {
    entry.file = openVerified(path);
  } catch (...) {
    removeQuietly(path);
    throw;
  }
  // The map keeps the data; the name goes now so nothing is left behind.
  removeQuietly(path);
  entry.temporary = true;
  for (const std::string& w : entry.report.warnings) entry.warnings.push_back(w);
  return entry;
}

FblCacheEntry FblCache::get(const FblCacheKey& key, const ReaderFactory& open_input, const CompressOptions& options) {
  std::vector<std::string> warnings;
  std::string why;
  if (!directoryWritable(dir_, why)) {
    // A read-only cache may still hold the entry.
    if (!dir_.empty()) {
      if (std::optional<FblFile> file = openEntry(key, &warnings)) {
        FblCacheEntry entry;
        entry.file = std::move(*file);
        entry.path = fblPath(key);
        entry.from_cache = true;
        entry.warnings = std::move(warnings);
        return entry;
      }
    }
    return compressTemporary(open_input, options, why, std::move(warnings));
  }
  FblCacheEntry entry;
  if (std::optional<FblFile> file = openEntry(key, &warnings)) {
    entry.file = std::move(*file);
    entry.path = fblPath(key);
    entry.from_cache = true;
    entry.warnings = std::move(warnings);
    return entry;
  }
  const std::string fbl_path = fblPath(key);
  CompressOptions o = options;
  o.overwrite = true;  // a damaged entry, or one another viewer just wrote
  // The .fbl first, then the sidecar: an entry is served only with both,
  // and each appears whole (temporary name + rename).
  removeQuietly(sidecarPath(key));
  entry.report = compressTractogram(open_input, fbl_path, o);
  entry.file = openVerified(fbl_path);
  writeSidecar(sidecarPath(key), key, entry.file.fileBytes());
  entry.path = fbl_path;
  entry.warnings = std::move(warnings);
  for (const std::string& w : entry.report.warnings) entry.warnings.push_back(w);
  removeSuperseded(key);
  evict(fbl_path);
  return entry;
}

FblCacheEntry FblCache::getFile(const std::string& input, const CompressOptions& options) {
  const FblCacheKey key = fblCacheKeyForFile(input, options);
  return get(key, [&]() { return openTractogram(input); }, options);
}

FblCacheEntry FblCache::getPhantom(const PhantomOptions& phantom, const CompressOptions& options) {
  validatePhantomOptions(phantom);
  return get(fblCacheKeyForPhantom(phantom, options), [&]() { return openPhantom(phantom); }, options);
}

void FblCache::removeSuperseded(const FblCacheKey& key) {
  // Entries of earlier versions of the same file (same path, another size,
  // mtime or content) can never be served again: drop them now rather than
  // letting them hold space until eviction.
  if (key.kind != "file") return;
  const std::string digest = key.digest();
  std::error_code ec;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path p = it->path();
    if (p.extension() != ".json" || p.stem() == digest || p.filename().string().front() == '.') continue;
    try {
      const std::optional<Sidecar> s = readSidecar(p.string());
      if (s && s->key.kind == "file" && s->key.path == key.path && s->key.options == key.options) {
        removeQuietly((fs::path(dir_) / (p.stem().string() + ".fbl")).string());
        removeQuietly(p.string());
      }
    } catch (const Error&) {
      // Another viewer's damaged entry: its own lookup deals with it.
    }
  }
}

uint64_t FblCache::evict(const std::string& keep) {
  struct Entry {
    fs::path path;
    uint64_t bytes;
    int64_t mtime;
  };
  std::vector<Entry> entries;
  uint64_t total = 0, freed = 0;
  const int64_t now_ns = int64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::system_clock::now().time_since_epoch())
                                     .count());
  const int64_t day_ns = int64_t(86400) * 1000000000;
  std::error_code ec;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path p = it->path();
    const std::string name = p.filename().string();
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    // Temporary files of OutputFile (".<name>.tmp-<pid>-<n>") left by a
    // crashed viewer; a day old, so a running compression is never touched.
    if (name.front() == '.' && name.find(".tmp-") != std::string::npos) {
      if (now_ns - mtimeNs(st) > day_ns) {
        removeQuietly(p.string());
        freed += uint64_t(st.st_size);
      }
      continue;
    }
    if (p.extension() != ".fbl") continue;
    entries.push_back({p, uint64_t(st.st_size), mtimeNs(st)});
    total += uint64_t(st.st_size);
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.mtime < b.mtime; });
  for (const Entry& e : entries) {
    if (total <= max_bytes_) break;
    if (!keep.empty() && fs::equivalent(e.path, keep, ec)) continue;
    removeQuietly(e.path.string());
    removeQuietly((e.path.parent_path() / (e.path.stem().string() + ".json")).string());
    total -= e.bytes;
    freed += e.bytes;
  }
  return freed;
}

}  // namespace fibscope
