// What .tck tracks and .tsf track scalars (MRtrix3) have in common.
//
// Both files are a text header followed by raw samples:
//
//   mrtrix tracks            (or "mrtrix track scalars"; MRtrix pads this line with spaces)
//   key: value               any number of lines; keys may repeat (roi, comment, ...)
//   datatype: Float32LE      Float32LE, Float32BE, Float64LE or Float64BE
//   file: . 632              the data starts at byte 632 of this same file
//   count: 300               streamlines, when the writer finished cleanly
//   END
//   <padding up to the data offset, MRtrix writes zeros>
//   <samples>
//
// A .tck holds x,y,z triplets in RAS+ millimetres; a NaN triplet closes each
// streamline and an Inf triplet ends the file. A .tsf holds one value per
// point laid out the same way, with single NaN and Inf values. Two NaN
// separators in a row are a legal zero-length streamline.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/byte_order.h"
#include "core/mapped_file.h"

namespace fibscope {

// One of the four sample types MRtrix allows in track files.
struct TckDataType {
  std::string name = "Float32LE";  // as written in the header
  size_t bytes = 4;                // 4 or 8
  bool big_endian = false;

  bool needsSwap() const { return big_endian == kHostIsLittleEndian; }
  // The DataArray dtype of values read from a .tsf of this type.
  const char* arrayDtype() const { return bytes == 8 ? "float64" : "float32"; }
};

// Parses "Float32LE", "Float32BE", "Float64LE" or "Float64BE", ignoring case
// as MRtrix does; nullopt for anything else.
std::optional<TckDataType> parseTckDataType(std::string_view name);

constexpr std::string_view kTckMagic = "mrtrix tracks";
constexpr std::string_view kTsfMagic = "mrtrix track scalars";

// What the header of a .tck or .tsf says.
struct TckHeaderInfo {
  std::vector<std::pair<std::string, std::string>> properties;  // every line, file order
  TckDataType datatype;
  uint64_t header_end = 0;            // first byte after the END line
  uint64_t data_offset = 0;           // from "file: . OFFSET"; header_end <= data_offset <= file size
  int64_t count = -1;                 // the "count" line; -1 when absent or not a number
  std::vector<std::string> warnings;  // malformed lines that were skipped
};

// Parses the header of a mapped track file whose first line must be `magic`.
// Safe on untrusted input: throws Error ("PATH: ...", one line) for a wrong
// first line, a missing END, a missing or unsupported datatype, a missing
// "file" line or a data offset inside the header or past the end of file.
TckHeaderInfo parseTckHeader(const MappedFile& file, std::string_view magic);

// Index of the first NaN or Inf among the `n` samples of `type` at `p`, or `n`
// if all are finite. Reads exactly `n * type.bytes` bytes; `p` may be unaligned.
size_t findNonFinite(const uint8_t* p, size_t n, const TckDataType& type);

enum class SampleKind { kFinite, kNaN, kInf };
SampleKind classifySample(const uint8_t* p, const TckDataType& type);

// Appends `n` samples at `p` to `out` as float (one bulk copy for native
// float32); same checks as decodeSamples.
void appendSamples(const uint8_t* p, size_t n, const TckDataType& type, std::vector<float>& out,
                   const std::string& path, uint64_t file_offset);

// Converts `n` samples at `p` to float into `out`. Float64 samples beyond the
// float range throw Error naming `path` and the byte offset (`file_offset` is
// the offset of `p` in the file). Samples must be finite (checked by caller).
void decodeSamples(const uint8_t* p, size_t n, const TckDataType& type, float* out, const std::string& path,
                   uint64_t file_offset);

// Appends `n` floats encoded as `type` to `out`.
void encodeSamples(const float* values, size_t n, const TckDataType& type, std::vector<uint8_t>& out);
// Appends `n` copies of one special value (NaN separator, Inf terminator).
void encodeRepeated(float value, size_t n, const TckDataType& type, std::vector<uint8_t>& out);

// The header a writer puts in front of its samples.
struct TckHeaderText {
  std::string text;                           // ends with "END\n"; text.size() == data offset
  uint64_t count_offset = 0;                  // where the count digits start
  static constexpr size_t kCountDigits = 20;  // enough for any uint64
};

// Keys a writer sets itself and never copies from the input's properties.
bool isTckWriterOwnedKey(std::string_view key);

// Builds a header: `magic`, the `properties` a track file can carry (owned
// keys are skipped; keys that could not be parsed back - empty, or holding
// ':' or line breaks - are dropped with a message appended to `dropped`),
// multi-line values as repeated keys, then datatype, a zero-padded count
// field for formatTckCount() to patch, "file: . OFFSET" and END.
TckHeaderText makeTckHeader(std::string_view magic, const std::vector<std::pair<std::string, std::string>>& properties,
                            const TckDataType& type, std::vector<std::string>* dropped);
// The fixed-width count digits, e.g. "00000000000000001000".
std::string formatTckCount(uint64_t count);

// The samples of a track file, read front to back through one buffer.
//
// The data is copied out with pread() rather than parsed in a map: on
// virtual machines (nested paging) touching mapped page-cache pages costs a
// TLB miss every 4 KiB (measured ~1 GB/s, even with MADV_POPULATE_READ
// ~2.5 GB/s), while the kernel copies the same pages at 7-13 GB/s through
// its huge-page direct map; the copy lands in a buffer that stays in L2 for
// the scan. Resident memory is the buffer alone,
// whatever the file size. Buffered bytes always start at a multiple of the
// sample size from the data offset, so samples are aligned in memory.
class TrackDataStream {
 public:
  // Opens `path` to read its bytes [begin, end). Throws Error if it cannot.
  TrackDataStream(const std::string& path, uint64_t begin, uint64_t end);
  ~TrackDataStream();
  TrackDataStream(const TrackDataStream&) = delete;
  TrackDataStream& operator=(const TrackDataStream&) = delete;

  // Buffered bytes: those of the file at [position(), position() + available()).
  const uint8_t* data() const { return bytes() + head_; }
  size_t available() const { return tail_ - head_; }
  uint64_t position() const { return next_ - (tail_ - head_); }
  uint64_t end() const { return end_; }
  // Forgets the first `n` buffered bytes (n <= available()).
  void consume(size_t n) { head_ += n; }
  // Buffers at least `n` bytes (n <= capacity()), fewer only at the end of
  // the data. Reads ahead as much as fits. Returns available().
  size_t capacity() const { return capacity_; }
  // Forgets the buffered bytes and goes on reading at `position` (in
  // [begin, end)), keeping the buffer: a scan of many ranges of one file.
  // Reads ahead stop at `soft_end` (a range's end) and go past it a little
  // at a time (kPastSoftEnd: the streamline that crosses it), so ranges
  // read their own bytes and hardly any of the next one's.
  void restart(uint64_t position, uint64_t soft_end) {
    head_ = tail_ = 0, next_ = position, soft_end_ = soft_end;
  }
  static constexpr size_t kPastSoftEnd = size_t(16) << 10;
  size_t fill(size_t n);

 private:
  uint8_t* bytes() { return reinterpret_cast<uint8_t*>(buffer_.data()); }
  const uint8_t* bytes() const { return reinterpret_cast<const uint8_t*>(buffer_.data()); }

  std::string path_;
  int fd_ = -1;
  // Float storage, so aligned native float32 samples are read as the floats
  // they are; everything else goes through bytes.
  std::vector<float> buffer_;
  size_t head_ = 0;  // bytes
  size_t tail_ = 0;
  size_t capacity_ = 0;
  uint64_t next_ = 0;  // file offset of buffer_[tail_]
  uint64_t end_ = 0;
  uint64_t soft_end_ = UINT64_MAX;  // see restart()
};

// The warning a reader gives when the header's count line is missing or
// differs from the `streamlines` the file holds (nullopt when it agrees);
// `header_count` < 0 for a count line that is not a number.
std::optional<std::string> tckCountWarning(bool has_count_line, int64_t header_count, uint64_t streamlines);

// `text` with control bytes replaced and cut to `max_chars`, for quoting file
// contents inside one-line messages.
std::string printableExcerpt(std::string_view text, size_t max_chars = 60);

}  // namespace fibscope
