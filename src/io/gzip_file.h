// Files read through zlib, which reads gzip and plain files alike: NIfTI
// volumes (.nii.gz) and gzip-compressed TrackVis files (DSI Studio's
// .trk.gz). Every failure is an Error naming the file and the offset in
// the decompressed data.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fibscope {

// Deflate's best ratio is 1032:1 (zlib's technical notes): a gzip file of n
// bytes cannot hold more than ~1032 n bytes, so a header claiming more is
// refused before anything is read (the NIfTI and TinyTrack readers).
inline constexpr uint64_t kMaxGzipInflateRatio = 1032;

// Whether the file at `path` starts with the gzip magic (1f 8b). False for
// a file that cannot be read (its reader then says why).
bool isGzipFile(const std::string& path);

class GzipFile {
 public:
  // Throws Error for a missing file, one that is not a regular file, or one
  // zlib cannot open.
  explicit GzipFile(const std::string& path);
  ~GzipFile();
  GzipFile(const GzipFile&) = delete;
  GzipFile& operator=(const GzipFile&) = delete;

  // Reads up to n bytes; fewer only at the end of the data. Throws for
  // corrupt or cut gzip streams ("the gzip stream is cut short").
  size_t read(void* buffer, size_t n);
  // Reads and drops n bytes; returns how many there were.
  uint64_t skip(uint64_t n, std::vector<unsigned char>& buffer);
  // Whether the file is gzip (valid after the first read).
  bool compressed() const;
  const std::string& path() const { return path_; }
  uint64_t fileSize() const { return size_; }
  // Decompressed bytes read so far.
  uint64_t offset() const { return offset_; }
  // Bytes of the file itself consumed so far (for progress against
  // fileSize()).
  uint64_t fileOffset() const;

 private:
  [[noreturn]] void failStream();

  std::string path_;
  void* file_ = nullptr;  // gzFile (zlib.h stays out of this header)
  uint64_t size_ = 0, offset_ = 0;
};

// A forward-only window on a GzipFile's decompressed bytes, for readers
// that parse records in place (the .trk reader): ensure() makes a range
// available and forgets what lies before it. Memory is the largest range
// asked for, and only as far as the data really goes: a lying record
// length cannot make it allocate more than twice what the file holds.
class GzipWindow {
 public:
  explicit GzipWindow(const std::string& path) : file_(path) {}

  // Makes the decompressed bytes [pos, pos + n) available; those before
  // `pos` may be dropped (so `pos` must not go back past an earlier call's,
  // nor beyond what that call made available). Returns how many there are:
  // n, fewer only at the end of the data.
  uint64_t ensure(uint64_t pos, uint64_t n);
  // The byte at decompressed offset `pos`, within the last ensure()'s range.
  const uint8_t* at(uint64_t pos) const { return buffer_.data() + (pos - base_); }
  const GzipFile& file() const { return file_; }

 private:
  GzipFile file_;
  std::vector<uint8_t> buffer_;
  uint64_t base_ = 0;  // decompressed offset of buffer_[0]
  size_t filled_ = 0;  // bytes of buffer_ holding data
  bool at_end_ = false;
};

}  // namespace fibscope
