#include "io/gzip_file.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/error.h"

namespace fibscope {
namespace {

gzFile handle(void* f) { return static_cast<gzFile>(f); }

// A window starts this big and doubles when a range does not fit; reads go
// at most kWindowStep at a time.
constexpr size_t kFirstWindow = size_t(64) << 10;
constexpr size_t kWindowStep = size_t(1) << 20;

}  // namespace

bool isGzipFile(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  unsigned char magic[2] = {0, 0};
  const bool gzip = std::fread(magic, 1, 2, f) == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
  std::fclose(f);
  return gzip;
}

GzipFile::GzipFile(const std::string& path) : path_(path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    errno = ec ? ec.value() : ENOENT;
    failErrno(path, "cannot open");
  }
  if (!std::filesystem::is_regular_file(status)) fail(path, "not a regular file");
  size_ = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  file_ = gzopen(path.c_str(), "rb");
  if (!file_) failErrno(path, "cannot open");
}

GzipFile::~GzipFile() { gzclose(handle(file_)); }

size_t GzipFile::read(void* buffer, size_t n) {
  size_t done = 0;
  while (done < n) {
    const unsigned want = unsigned(std::min<size_t>(n - done, INT_MAX / 2));
    const int got = gzread(handle(file_), static_cast<char*>(buffer) + done, want);
    if (got < 0) failStream();
    done += size_t(got);
    offset_ += uint64_t(got);
    if (unsigned(got) < want) {
      int code = Z_OK;
      gzerror(handle(file_), &code);
      if (code == Z_BUF_ERROR) failAt(path_, offset_, "the gzip stream is cut short (unexpected end of file)");
      if (code != Z_OK) failStream();
      break;
    }
  }
  return done;
}

uint64_t GzipFile::skip(uint64_t n, std::vector<unsigned char>& buffer) {
  uint64_t done = 0;
  while (done < n) {
    const size_t want = size_t(std::min<uint64_t>(n - done, buffer.size()));
    const size_t got = read(buffer.data(), want);
    done += got;
    if (got < want) break;
  }
  return done;
}

bool GzipFile::compressed() const { return gzdirect(handle(file_)) == 0; }

uint64_t GzipFile::fileOffset() const {
  const z_off_t at = gzoffset(handle(file_));
  return at < 0 ? 0 : std::min<uint64_t>(uint64_t(at), size_);
}

void GzipFile::failStream() {
  int code = Z_OK;
  const char* message = gzerror(handle(file_), &code);
  if (code == Z_ERRNO) failErrno(path_, "read error at byte " + std::to_string(offset_));
  failAt(path_, offset_, std::string("corrupt gzip data (") + (message ? message : "zlib error") + ")");
}

uint64_t GzipWindow::ensure(uint64_t pos, uint64_t n) {
  if (pos < base_ || pos > base_ + filled_) fail(file_.path(), "internal: the window went back or skipped");
  const uint64_t have = base_ + filled_ - pos;
  if (have >= n || at_end_) return std::min(n, have);
  // More is needed: only now forget what lies before pos (moving what is
  // left, less than a record), not on every call, which would move the
  // whole window once per streamline.
  const size_t drop = size_t(pos - base_);
  if (drop > 0) std::memmove(buffer_.data(), buffer_.data() + drop, filled_ - drop);  // (an empty buffer has no data())
  filled_ -= drop;
  base_ = pos;
  // Read in steps, growing by doubling only while data keeps coming.
  while (filled_ < n && !at_end_) {
    if (filled_ == buffer_.size()) buffer_.resize(std::max(buffer_.size() * 2, kFirstWindow));
    const size_t want = std::min(buffer_.size() - filled_, kWindowStep);
    const size_t got = file_.read(buffer_.data() + filled_, want);
    filled_ += got;
    at_end_ = got < want;
  }
  return std::min<uint64_t>(n, filled_);
}

}  // namespace fibscope
