// The viewer's cache of compressed copies: tractogram -> .fbl, kept in the
// user cache directory so that a second open of a large file skips
// compression.
//
// Directory: $FIBSCOPE_CACHE_DIR, else $XDG_CACHE_HOME/fibscope, else
// $HOME/.cache/fibscope (created on demand).
//
// An entry is "<digest>.fbl" plus the sidecar "<digest>.json" holding the
// key's fields. The digest names the entry; a lookup re-reads the sidecar
// and compares every field with the key of the input as it is now, so a
// digest collision or a stale entry is never served. The key of a file is
//   - its canonical absolute path, size and modification time (ns),
//   - a CRC-32C of kFblCacheSampleBlocks blocks of kFblCacheSampleBlockBytes
//     spread evenly over the file, the first and the last included (an
//     edit that keeps size and mtime is caught when it touches a sampled
//     block; hashing the whole file would cost as much as reading it),
//   - the .fbl format and fiblet codec versions, and the compression
//     options that change the output (not the thread count: the output
//     does not depend on it).
// The phantom's key is its options (count, seed, step, ...) and
// kPhantomGeneratorVersion instead of path/size/mtime/hash.
//
// Writes are atomic: the .fbl is written under a temporary name in the cache
// directory and renamed (FblWriter), then the sidecar likewise, so a viewer
// running beside another never sees half an entry. A cached .fbl that fails
// FblFile::open, its checksums or its codec header is deleted and rebuilt
// with a warning. When the directory cannot be written, the copy goes to a
// temporary file that is unlinked once mapped (warned once per FblCache),
// never an error. After a store, the least recently used entries (by the
// .fbl's mtime, refreshed on every hit) are evicted down to the size cap:
// $FIBSCOPE_CACHE_MAX_BYTES, default 20 GiB.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "codec/compressor.h"
#include "codec/fbl_file.h"
#include "phantom/phantom.h"

namespace fibscope {

// Bump when the phantom generator's output for the same options changes.
inline constexpr uint32_t kPhantomGeneratorVersion = 1;
// Bump when the key's fields or their meaning change.
// 2: per-point arrays are stored (dpv sections); older entries lack them.
inline constexpr uint32_t kFblCacheKeyVersion = 2;

inline constexpr size_t kFblCacheSampleBlocks = 16;
inline constexpr uint64_t kFblCacheSampleBlockBytes = uint64_t(64) << 10;
inline constexpr uint64_t kFblCacheDefaultMaxBytes = uint64_t(20) << 30;

struct FblCacheKey {
  std::string kind;        // "file" or "phantom"
  std::string path;        // file: canonical absolute path
  uint64_t size = 0;       // file: bytes
  int64_t mtime_ns = 0;    // file: modification time, ns since the epoch
  uint32_t sample_crc = 0; // file: CRC-32C of the sampled blocks (fblCacheSampledRanges)
  std::string phantom;     // phantom: its options, canonical text
  uint32_t phantom_version = 0;
  uint32_t format_version = 0;  // fbl::kFormatVersion
  uint32_t codec_version = 0;   // kFibletCodecVersion
  std::string options;          // fblCacheOptionsText of the compression options
  uint32_t key_version = kFblCacheKeyVersion;

  bool operator==(const FblCacheKey&) const = default;
  // Canonical JSON of every field (the sidecar's "key").
  std::string json() const;
  // 16 hex digits (64-bit FNV-1a of json()): the entry's file name stem.
  std::string digest() const;
};

// The byte ranges [offset, offset + bytes) hashed for a file of `size`
// bytes: the whole file when it is at most kFblCacheSampleBlocks blocks,
// else kFblCacheSampleBlocks blocks at evenly spaced offsets from 0 to
// size - block (first and last block included), in increasing order.
std::vector<std::pair<uint64_t, uint64_t>> fblCacheSampledRanges(uint64_t size);

// The options of `options` that change the .fbl's bytes, as canonical text.
std::string fblCacheOptionsText(const CompressOptions& options);

// The key of an input file as it is now. Throws Error naming `path` when it
// cannot be stat'ed or read (missing file, directory without header, ...).
// A TRX directory is keyed by its header.json plus every member's size and
// mtime.
FblCacheKey fblCacheKeyForFile(const std::string& path, const CompressOptions& options = {});
// The key of the built-in phantom with these options.
FblCacheKey fblCacheKeyForPhantom(const PhantomOptions& phantom, const CompressOptions& options = {});

// $FIBSCOPE_CACHE_DIR, $XDG_CACHE_HOME/fibscope, $HOME/.cache/fibscope, or
// "" when none of them is set.
std::string defaultFblCacheDir();
// $FIBSCOPE_CACHE_MAX_BYTES when a positive integer, else kFblCacheDefaultMaxBytes.
uint64_t defaultFblCacheMaxBytes();

// A compressed copy ready to use.
struct FblCacheEntry {
  FblFile file;              // opened, every checksum verified
  std::string path;          // the cached .fbl ("" for an unlinked temporary copy)
  bool from_cache = false;   // true: no compression ran
  bool temporary = false;    // the cache directory was not writable
  CompressReport report;     // when compressed (from_cache false)
  std::vector<std::string> warnings;  // reader/compressor warnings, cache problems
};

class FblCache {
 public:
  // `dir` "" = defaultFblCacheDir() (and a temporary file when that is ""
  // too); `max_bytes` 0 = defaultFblCacheMaxBytes().
  explicit FblCache(std::string dir = {}, uint64_t max_bytes = 0);

  const std::string& dir() const { return dir_; }
  uint64_t maxBytes() const { return max_bytes_; }

  // Paths of the entry for `key` (whether or not it exists).
  std::string fblPath(const FblCacheKey& key) const;
  std::string sidecarPath(const FblCacheKey& key) const;

  // The cached .fbl for `key`, or nothing. Served only when the sidecar's
  // key equals `key` field by field, the .fbl opens, its checksums verify
  // and its codec header is valid; a bad entry is deleted (a warning is
  // appended to `warnings` when given). A hit refreshes the entry's mtime
  // (LRU).
  std::optional<std::string> lookup(const FblCacheKey& key, std::vector<std::string>* warnings = nullptr);
  // lookup(fblCacheKeyForFile(input, options)). Throws as that does.
  std::optional<std::string> lookup(const std::string& input, const CompressOptions& options = {});

  // The entry for `key`: the cached copy, else `open_input` compressed into
  // the cache (or into a temporary file when the directory is not
  // writable), then opened and verified. compressTractogram's errors
  // (bad input, cancellation through the reader) propagate; nothing is left
  // in the cache then. options.overwrite is ignored.
  FblCacheEntry get(const FblCacheKey& key, const ReaderFactory& open_input, const CompressOptions& options);
  // get() for an input file (openInput by extension) or the phantom.
  FblCacheEntry getFile(const std::string& input, const CompressOptions& options = {});
  FblCacheEntry getPhantom(const PhantomOptions& phantom, const CompressOptions& options = {});

  // Deletes least recently used entries (and stale temporary files older
  // than a day) until the .fbl files total at most maxBytes(); `keep` (a
  // .fbl path) is never deleted. Returns the bytes freed.
  uint64_t evict(const std::string& keep = {});

 private:
  // The verified entry for `key`, or nothing (a damaged one is deleted).
  std::optional<FblFile> openEntry(const FblCacheKey& key, std::vector<std::string>* warnings);
  FblCacheEntry compressTemporary(const ReaderFactory& open_input, const CompressOptions& options,
                                  const std::string& reason, std::vector<std::string> warnings);
  // Deletes the entries of other versions of key's file.
  void removeSuperseded(const FblCacheKey& key);
  std::string dir_;
  uint64_t max_bytes_;
  bool warned_unwritable_ = false;
};

}  // namespace fibscope
