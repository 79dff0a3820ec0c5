// The viewer's octree cache (issue 16 item 5): the SVO of a tube model kept
// beside the .fbl cache (the same directory: FIBSCOPE_CACHE_DIR, ...;
// codec/fbl_cache.h), so a second request of the same tubes loads the tree
// instead of voxelising again.
//
// An entry is "<digest>.svo" (svo/svo_file.h) plus the sidecar
// "<digest>.svo.json" holding the key's text. The key names what the tree
// is built from, as the .fbl cache's key does for a compressed copy:
//   - per model, its .fbl's identity: path, size and a CRC-32C of its
//     section checksums (the .fbl's content: a cached .fbl's path is its
//     own cache digest, a model opened as .fbl changes its checksums with
//     its content), and a hash of the fiber ids taken from it, in order;
//   - the radius (constant, or the per-fiber array and its range), the
//     resampling tolerance, the voxel (0: chosen from the data), curved;
//   - kSvoFileVersion and kSvoCacheKeyVersion.
// A lookup compares the sidecar's text with the key's whole, so a digest
// collision or a stale entry is never served; an entry that fails
// readSvoTree (truncated, damaged) is deleted and reported as a warning,
// and the caller builds again. Writes are atomic (temporary + rename, the
// tree first, then the sidecar). After a store, .svo entries are evicted
// least recently used first (by mtime, refreshed on a hit) down to the
// .fbl cache's cap ($FIBSCOPE_CACHE_MAX_BYTES), counted apart from the .fbl
// files (FblCache::evict counts those).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "codec/fbl_file.h"
#include "svo/svo_build.h"

namespace fibscope {

// Bump when the key's fields or their meaning change.
inline constexpr uint32_t kSvoCacheKeyVersion = 1;

struct SvoCacheKey {
  std::string text;  // canonical JSON of every field
  // 16 hex digits (64-bit FNV-1a of text): the entry's file name stem.
  std::string digest() const;
};

// One model's part of the key: its .fbl and the fibers taken from it, in order.
std::string svoCacheModelText(const FblFile& fbl, const std::vector<uint32_t>& fibers);
// The key of a tree built from these models' fibers with these options.
// `radius` the tube radius's text (constant mm, or array and range).
SvoCacheKey svoCacheKey(const std::vector<std::string>& model_texts, const std::string& radius, float tolerance_mm,
                        float voxel_mm, bool curved);

class SvoCache {
 public:
  // `dir` "" = defaultFblCacheDir() (no caching when that is "" too);
  // `max_bytes` 0 = defaultFblCacheMaxBytes().
  explicit SvoCache(std::string dir = {}, uint64_t max_bytes = 0);
  const std::string& dir() const { return dir_; }
  bool enabled() const { return !dir_.empty(); }
  std::string treePath(const SvoCacheKey& key) const;
  std::string sidecarPath(const SvoCacheKey& key) const;

  // The cached tree of `key`, or nothing (a damaged entry is deleted, a
  // warning appended). Never throws for a bad entry.
  std::optional<SvoTree> lookup(const SvoCacheKey& key, std::vector<std::string>& warnings,
                                uint64_t segment_count = UINT64_MAX);
  // Stores `tree` under `key` and evicts; a directory that cannot be
  // written is a warning, never an error.
  void store(const SvoCacheKey& key, const SvoTree& tree, std::vector<std::string>& warnings);
  // Deletes least recently used .svo entries until they total at most the
  // cap; `keep` is never deleted. Returns the bytes freed.
  uint64_t evict(const std::string& keep = {});

 private:
  std::string dir_;
  uint64_t max_bytes_;
};

}  // namespace fibscope
