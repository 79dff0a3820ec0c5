// An anonymous scratch file for data that grows with the input and is
// needed again only at the end (per-fiber tables while compressing), so
// that memory stays bounded whatever the input size.
//
// The file has no name (O_TMPFILE, or a name unlinked right after mkstemp)
// in the directory given, normally the output's, so it is on the same disk
// as the output and disappears with the process, however it ends.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace fibscope {

class SpillFile {
 public:
  // `directory`: where the data goes; `what` names it in error messages.
  SpillFile(const std::string& directory, std::string what);
  ~SpillFile();
  SpillFile(SpillFile&& other) noexcept;
  SpillFile& operator=(SpillFile&&) = delete;
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  void write(const void* data, size_t bytes);
  uint64_t size() const { return written_; }
  // Hands the whole content back in blocks of at most 1 MiB, in order.
  void readBack(const std::function<void(const uint8_t* data, size_t bytes)>& consume);

 private:
  void flush();
  std::string what_;
  int fd_ = -1;
  std::vector<uint8_t> buffer_;
  uint64_t written_ = 0;
  uint64_t flushed_ = 0;
};

}  // namespace fibscope
