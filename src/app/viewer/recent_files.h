// The viewer's "recent files" list: the tractograms opened from the UI, a
// script or the command line, newest first, at most kMaxRecentFiles, kept
// as JSON next to the .fbl cache (defaultFblCacheDir()/recent_files.json)
// so that the next session offers them again.
//
// File: {"version": 1, "files": ["/abs/a.tck", ...]}. A missing, unreadable
// or malformed file is an empty list (the list is a convenience, never a
// reason to stop the viewer); entries that are not strings are skipped.
// Writes go to a temporary name and are renamed, so a viewer running beside
// another never reads half a list.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace fibscope {

inline constexpr size_t kMaxRecentFiles = 10;

// defaultFblCacheDir() + "/recent_files.json", or "" when no cache
// directory can be named (no HOME): then nothing is persisted.
std::string defaultRecentFilesPath();

// The list stored at `json_path` (empty on any problem), at most
// kMaxRecentFiles entries, duplicates dropped; with `drop_missing`, files
// that no longer exist are left out.
std::vector<std::string> loadRecentFiles(const std::string& json_path, bool drop_missing = true);

// `list` with `path` (made absolute) moved or added to the front, cut to
// kMaxRecentFiles. An empty path (the phantom) leaves the list as it is.
std::vector<std::string> addRecentFile(std::vector<std::string> list, const std::string& path);

// Writes `list` to `json_path` (creating the directory); returns "" or a
// one-line reason when it could not be written.
std::string saveRecentFiles(const std::string& json_path, const std::vector<std::string>& list);

}  // namespace fibscope
