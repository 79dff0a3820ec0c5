// A file written under a temporary name and renamed into place on commit().
//
// A crash, an exception or a full disk never leaves a half-written file
// under the final name: until commit() the data lives in
// "<dir>/.<name>.tmp-<pid>-<n>", which the destructor removes.
// Writes are buffered (1 MiB); seekWrite() patches earlier bytes (headers
// whose counts are known only at the end).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fibscope {

class OutputFile {
 public:
  // Fails with a one-line Error if `path` exists and !overwrite, or if the
  // directory is not writable.
  OutputFile(const std::string& path, bool overwrite);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  void write(const void* data, size_t bytes);
  void write(const std::string& s) { write(s.data(), s.size()); }
  // Overwrites bytes at an absolute offset already written.
  void writeAt(uint64_t offset, const void* data, size_t bytes);
  uint64_t size() const { return written_; }
  // Flushes, fsyncs and renames to the final path.
  void commit();
  const std::string& path() const { return path_; }

 private:
  void flush();
  std::string path_;
  std::string temp_path_;
  int fd_ = -1;
  bool committed_ = false;
  std::vector<uint8_t> buffer_;
  uint64_t written_ = 0;   // logical size including the buffer
  uint64_t flushed_ = 0;   // bytes already in the file
};

// Throws Error if `path` exists and !overwrite: "PATH: exists (use --force to overwrite)".
void checkOverwrite(const std::string& path, bool overwrite);

}  // namespace fibscope
