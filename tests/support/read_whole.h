// A whole file through the streaming interface, for the readers' tests:
// every chunk checked, progress recorded after each.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.h"
#include "io/reader.h"

namespace fibscope::test {

struct WholeRead {
  Tractogram all;
  TractogramHeader header;
  std::vector<std::string> warnings;
  std::vector<uint64_t> progress;  // bytesRead after each chunk, then at the end
};

inline WholeRead readWhole(const std::string& path, size_t max_points) {
  WholeRead r;
  auto reader = openTractogram(path);
  Tractogram chunk;
  while (reader->read(chunk, max_points)) {
    EXPECT_EQ(chunk.validate(), "");
    r.all.append(chunk);
    r.progress.push_back(reader->bytesRead());
  }
  r.progress.push_back(reader->bytesRead());
  r.header = reader->header();
  r.warnings = reader->warnings();
  return r;
}

// The Error reading `path` gives ("" when none).
inline std::string readError(const std::string& path) {
  try {
    readWhole(path, size_t(1) << 16);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace fibscope::test
