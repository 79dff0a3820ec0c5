#include "app/viewer/viewer_svo_cache.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "codec/fbl_cache.h"
#include "core/checksum.h"
#include "core/error.h"
#include "core/output_file.h"
#include "svo/svo_file.h"

namespace fibscope {
namespace fs = std::filesystem;
namespace {

std::string hex64(uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016" PRIx64, v);
  return text;
}

std::string exact(float v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", double(v));
  return text;
}

void removeQuietly(const std::string& path) {
  std::error_code ec;
  fs::remove(path, ec);
}

std::optional<std::string> readSmallFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (text.size() > (size_t(1) << 20)) return std::nullopt;
  return text;
}

}  // namespace

std::string SvoCacheKey::digest() const {
  uint64_t h = 0xcbf29ce484222325ull;
  for (const unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return hex64(h);
}

std::string svoCacheModelText(const FblFile& fbl, const std::vector<uint32_t>& fibers) {
  uint32_t content = 0;
  for (const FblSection& s : fbl.sections()) {
    content = crc32c(s.name.data(), s.name.size(), content);
    content = crc32c(&s.checksum, sizeof(s.checksum), content);
    content = crc32c(&s.bytes, sizeof(s.bytes), content);
  }
  nlohmann::json j;
  j["fbl"] = fbl.path();
  j["bytes"] = fbl.fileBytes();
  j["content_crc"] = content;
  j["fibers"] = fibers.size();
  j["fibers_crc"] = crc32c(fibers.data(), fibers.size() * sizeof(uint32_t));
  return j.dump();
}

SvoCacheKey svoCacheKey(const std::vector<std::string>& model_texts, const std::string& radius, float tolerance_mm,
                        float voxel_mm, bool curved) {
  nlohmann::json j;
  j["models"] = nlohmann::json::array();
  for (const std::string& m : model_texts) j["models"].push_back(nlohmann::json::parse(m));
  j["radius"] = radius;
  j["tolerance_mm"] = exact(tolerance_mm);
  j["voxel_mm"] = exact(voxel_mm);
  j["curved"] = curved;
  j["svo_file_version"] = kSvoFileVersion;
  j["key_version"] = kSvoCacheKeyVersion;
  return SvoCacheKey{j.dump()};
}

SvoCache::SvoCache(std::string dir, uint64_t max_bytes)
    : dir_(dir.empty() ? defaultFblCacheDir() : std::move(dir)),
      max_bytes_(max_bytes ? max_bytes : defaultFblCacheMaxBytes()) {}

std::string SvoCache::treePath(const SvoCacheKey& key) const { return dir_ + "/" + key.digest() + ".svo"; }
std::string SvoCache::sidecarPath(const SvoCacheKey& key) const { return dir_ + "/" + key.digest() + ".svo.json"; }

std::optional<SvoTree> SvoCache::lookup(const SvoCacheKey& key, std::vector<std::string>& warnings,
                                        uint64_t segment_count) {
  if (!enabled()) return std::nullopt;
  const std::string tree_path = treePath(key), sidecar = sidecarPath(key);
  std::error_code ec;
  if (!fs::exists(tree_path, ec)) return std::nullopt;
  const std::optional<std::string> text = readSmallFile(sidecar);
  bool same = false;
  if (text) {
    try {
      same = nlohmann::json::parse(*text).at("key").get<std::string>() == key.text;
    } catch (const nlohmann::json::exception&) {
      same = false;
    }
  }
  if (!same) return std::nullopt;  // another key's entry of the same digest, or no sidecar yet: built again
  try {
    SvoTree tree = readSvoTree(tree_path, segment_count);
    fs::last_write_time(tree_path, fs::file_time_type::clock::now(), ec);  // LRU
    return tree;
  } catch (const Error& e) {
    warnings.push_back(std::string(e.what()) + "; the cached octree is deleted and built again");
    removeQuietly(tree_path);
    removeQuietly(sidecar);
    return std::nullopt;
  }
}

void SvoCache::store(const SvoCacheKey& key, const SvoTree& tree, std::vector<std::string>& warnings) {
  if (!enabled()) return;
  try {
    std::error_code ec;
    fs::create_directories(dir_, ec);
    writeSvoTree(treePath(key), tree);
    nlohmann::json j;
    j["key"] = key.text;
    j["svo_bytes"] = fs::file_size(treePath(key));
    OutputFile out(sidecarPath(key), /*overwrite=*/true);
    out.write(j.dump(1) + "\n");
    out.commit();
    evict(treePath(key));
  } catch (const std::exception& e) {
    warnings.push_back(std::string("octree cache: ") + e.what() + " (not cached)");
  }
}

uint64_t SvoCache::evict(const std::string& keep) {
  struct Entry {
    fs::path path;
    uint64_t bytes;
    fs::file_time_type mtime;
  };
  std::vector<Entry> entries;
  uint64_t total = 0, freed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path p = it->path();
    if (p.extension() != ".svo" || !it->is_regular_file(ec)) continue;
    const uint64_t bytes = it->file_size(ec);
    entries.push_back({p, bytes, it->last_write_time(ec)});
    total += bytes;
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.mtime < b.mtime; });
  for (const Entry& e : entries) {
    if (total <= max_bytes_) break;
    if (!keep.empty() && fs::equivalent(e.path, keep, ec)) continue;
    removeQuietly(e.path.string());
    removeQuietly(e.path.string() + ".json");
    total -= e.bytes;
    freed += e.bytes;
  }
  return freed;
}

}  // namespace fibscope
