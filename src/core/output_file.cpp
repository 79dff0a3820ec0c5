#include "core/output_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/error.h"
#include "core/interrupt_cleanup.h"

namespace fibscope {
namespace {

constexpr size_t kBufferBytes = size_t(1) << 20;

void writeFully(int fd, const uint8_t* p, size_t n, const std::string& path) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      failErrno(path, "write failed");
    }
    p += w;
    n -= static_cast<size_t>(w);
  }
}

}  // namespace

void checkOverwrite(const std::string& path, bool overwrite) {
  std::error_code ec;
  if (!overwrite && std::filesystem::exists(path, ec)) fail(path, "exists (use --force to overwrite)");
}

OutputFile::OutputFile(const std::string& path, bool overwrite) : path_(path) {
  checkOverwrite(path, overwrite);
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path p(path);
  const std::string dir = p.has_parent_path() ? p.parent_path().string() + "/" : std::string();
  temp_path_ = dir + "." + p.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
               std::to_string(counter++);
  registerTemporaryPath(temp_path_);  // removed if the process is interrupted
  fd_ = ::open(temp_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    unregisterTemporaryPath(temp_path_);
    failErrno(path, "cannot create output file");
  }
  buffer_.reserve(kBufferBytes);
}

OutputFile::~OutputFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_) {
    ::unlink(temp_path_.c_str());
    unregisterTemporaryPath(temp_path_);
  }
}

void OutputFile::write(const void* data, size_t bytes) {
  const auto* p = static_cast<const uint8_t*>(data);
  written_ += bytes;
  if (buffer_.size() + bytes > kBufferBytes) {
    flush();
    if (bytes >= kBufferBytes) {
      writeFully(fd_, p, bytes, path_);
      flushed_ += bytes;
      return;
    }
  }
  buffer_.insert(buffer_.end(), p, p + bytes);
}

void OutputFile::writeAt(uint64_t offset, const void* data, size_t bytes) {
  if (offset + bytes > written_) fail(path_, "internal error: patch past the end of the output");
  const auto* p = static_cast<const uint8_t*>(data);
  // Part in the file already.
  if (offset < flushed_) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(bytes, flushed_ - offset));
    size_t done = 0;
    while (done < n) {
      const ssize_t w = ::pwrite(fd_, p + done, n - done, static_cast<off_t>(offset + done));
      if (w < 0) {
        if (errno == EINTR) continue;
        failErrno(path_, "write failed");
      }
      done += static_cast<size_t>(w);
    }
    p += n;
    offset += n;
    bytes -= n;
  }
  // Part still in the buffer.
  if (bytes > 0) std::memcpy(buffer_.data() + (offset - flushed_), p, bytes);
}

void OutputFile::flush() {
  if (buffer_.empty()) return;
  writeFully(fd_, buffer_.data(), buffer_.size(), path_);
  flushed_ += buffer_.size();
  buffer_.clear();
}

void OutputFile::commit() {
  flush();
  if (::fsync(fd_) != 0) failErrno(path_, "fsync failed");
  if (::close(fd_) != 0) {
    fd_ = -1;
    failErrno(path_, "close failed");
  }
  fd_ = -1;
  if (::rename(temp_path_.c_str(), path_.c_str()) != 0) failErrno(path_, "cannot rename temporary file into place");
  committed_ = true;
  unregisterTemporaryPath(temp_path_);
}

}  // namespace fibscope
