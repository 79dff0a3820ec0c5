#include "core/error.h"

#include <cerrno>
#include <cstring>

namespace fibscope {

void fail(const std::string& path, const std::string& message) {
  throw Error(path + ": " + message);
}

void failAt(const std::string& path, uint64_t offset, const std::string& message) {
  throw Error(path + ": byte " + std::to_string(offset) + ": " + message);
}

void failErrno(const std::string& path, const std::string& message) {
  const int saved = errno;
  throw Error(path + ": " + message + ": " + std::strerror(saved));
}

}  // namespace fibscope
