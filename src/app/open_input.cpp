#include "app/open_input.h"

#include <algorithm>
#include <filesystem>

#include "codec/fbl_reader.h"

namespace fibscope {

bool isFblPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".fbl";
}

std::unique_ptr<TractogramReader> openInput(const std::string& path) {
  if (isFblPath(path)) return openFbl(path);
  return openTractogram(path);
}

}  // namespace fibscope
