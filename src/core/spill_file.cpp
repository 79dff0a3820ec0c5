#include "core/spill_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "core/error.h"

namespace fibscope {

namespace {
constexpr size_t kBlock = size_t(1) << 20;
}

SpillFile::SpillFile(const std::string& directory, std::string what) : what_(std::move(what)) {
  const std::string dir = directory.empty() ? "." : directory;
#ifdef O_TMPFILE
  fd_ = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
#endif
  if (fd_ < 0) {
    // Filesystems without O_TMPFILE: a named file, unlinked at once.
    std::string name = dir + "/.fibscope-spill-XXXXXX";
    fd_ = ::mkstemp(name.data());
    if (fd_ < 0) failErrno(dir, "cannot create a scratch file for the " + what_);
    ::unlink(name.c_str());
  }
  buffer_.reserve(kBlock);
}

SpillFile::~SpillFile() {
  if (fd_ >= 0) ::close(fd_);
}

SpillFile::SpillFile(SpillFile&& other) noexcept
    : what_(std::move(other.what_)),
      fd_(std::exchange(other.fd_, -1)),
      buffer_(std::move(other.buffer_)),
      written_(other.written_),
      flushed_(other.flushed_) {}

void SpillFile::write(const void* data, size_t bytes) {
  const auto* p = static_cast<const uint8_t*>(data);
  while (bytes > 0) {
    const size_t take = std::min(bytes, kBlock - buffer_.size());
    buffer_.insert(buffer_.end(), p, p + take);
    p += take;
    bytes -= take;
    written_ += take;
    if (buffer_.size() == kBlock) flush();
  }
}

void SpillFile::flush() {
  size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::pwrite(fd_, buffer_.data() + done, buffer_.size() - done, off_t(flushed_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) failErrno("scratch file", "cannot write the " + what_);
    done += size_t(n);
  }
  flushed_ += buffer_.size();
  buffer_.clear();
}

void SpillFile::readBack(const std::function<void(const uint8_t*, size_t)>& consume) {
  flush();
  std::vector<uint8_t> block(kBlock);
  uint64_t offset = 0;
  while (offset < flushed_) {
    const size_t want = size_t(std::min<uint64_t>(kBlock, flushed_ - offset));
    const ssize_t n = ::pread(fd_, block.data(), want, off_t(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) failErrno("scratch file", "cannot read back the " + what_);
    consume(block.data(), size_t(n));
    offset += uint64_t(n);
  }
}

}  // namespace fibscope
