#include "app/viewer/recent_files.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "codec/fbl_cache.h"
#include "core/error.h"
#include "core/output_file.h"

namespace fibscope {
namespace {

constexpr int kRecentFilesVersion = 1;

std::string absolutePath(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  return ec ? path : absolute.lexically_normal().string();
}

}  // namespace

std::string defaultRecentFilesPath() {
  const std::string dir = defaultFblCacheDir();
  return dir.empty() ? std::string() : (std::filesystem::path(dir) / "recent_files.json").string();
}

std::vector<std::string> loadRecentFiles(const std::string& json_path, bool drop_missing) {
  std::vector<std::string> list;
  if (json_path.empty()) return list;
  std::ifstream in(json_path, std::ios::binary);
  if (!in) return list;
  std::ostringstream text;
  text << in.rdbuf();
  // No exceptions from the parser: a damaged file is an empty list.
  const nlohmann::json json = nlohmann::json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (!json.is_object() || !json.contains("files") || !json["files"].is_array()) return list;
  for (const nlohmann::json& entry : json["files"]) {
    if (list.size() >= kMaxRecentFiles) break;
    if (!entry.is_string()) continue;
    const std::string path = entry.get<std::string>();
    if (path.empty() || std::find(list.begin(), list.end(), path) != list.end()) continue;
    std::error_code ec;
    if (drop_missing && !std::filesystem::exists(path, ec)) continue;
    list.push_back(path);
  }
  return list;
}

std::vector<std::string> addRecentFile(std::vector<std::string> list, const std::string& path) {
  if (path.empty()) return list;
  const std::string absolute = absolutePath(path);
  list.erase(std::remove(list.begin(), list.end(), absolute), list.end());
  list.insert(list.begin(), absolute);
  if (list.size() > kMaxRecentFiles) list.resize(kMaxRecentFiles);
  return list;
}

std::string saveRecentFiles(const std::string& json_path, const std::vector<std::string>& list) {
  if (json_path.empty()) return "no cache directory to keep the recent files in";
  nlohmann::json json;
  json["version"] = kRecentFilesVersion;
  json["files"] = nlohmann::json::array();
  for (size_t i = 0; i < list.size() && i < kMaxRecentFiles; ++i) json["files"].push_back(list[i]);
  try {
    std::error_code ec;
    const std::filesystem::path parent = std::filesystem::path(json_path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    OutputFile out(json_path, /*overwrite=*/true);
    // Paths are arbitrary bytes on Linux: replace invalid UTF-8 rather than throw.
    out.write(json.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
    out.commit();
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

}  // namespace fibscope
