// Read-only memory map of a whole file (RAII).
//
// Readers parse straight out of the map: no copies, and the page cache does
// the I/O, which is how a 100 GB file is read in bounded resident memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace fibscope {

class MappedFile {
 public:
  MappedFile() = default;
  // Maps `path`; throws Error naming the path when it cannot be opened.
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(MappedFile&& other) noexcept;
  MappedFile& operator=(MappedFile&& other) noexcept;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const uint8_t* data() const { return data_; }
  size_t size() const { return size_; }
  const std::string& path() const { return path_; }
  std::string_view view() const { return {reinterpret_cast<const char*>(data_), size_}; }
  // Tells the kernel the map will be read front to back (large read-ahead).
  void adviseSequential() const;
  // Lets the kernel drop pages before `offset` from this process (bounded RSS).
  void release(size_t begin, size_t end) const;

 private:
  std::string path_;
  const uint8_t* data_ = nullptr;
  size_t size_ = 0;
};

}  // namespace fibscope
