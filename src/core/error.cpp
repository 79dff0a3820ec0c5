#include "core/error.h"

#include <cerrno>
#include <cstring>

namespace fibscope {

std::string oneLine(std::string message) {
  for (char& c : message) {
    const auto b = static_cast<unsigned char>(c);
    if (c == '\n' || c == '\r') c = ' ';
    else if (b < 0x20 || b == 0x7f) c = '?';
  }
  while (!message.empty() && message.back() == ' ') message.pop_back();
  return message;
}

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
