#include "io/tck_format.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "core/error.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace fibscope {
namespace {

std::string_view strip(std::string_view s) {
  const char* kSpace = " \t\r\v\f";
  const size_t b = s.find_first_not_of(kSpace);
  if (b == std::string_view::npos) return {};
  const size_t e = s.find_last_not_of(kSpace);
  return s.substr(b, e - b + 1);
}

std::optional<uint64_t> parseUnsigned(std::string_view s) {
  uint64_t v = 0;
  if (s.empty()) return std::nullopt;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

bool isAllDigits(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

std::string quoted(std::string_view s) {
  std::string out = "'";
  out += printableExcerpt(s);
  return out += '\'';
}

// The value of a key that must appear at most once with one meaning
// (datatype, file): repeated identical lines are tolerated.
std::optional<std::string> singleValue(const std::string& path, const TckHeaderInfo& info, std::string_view key) {
  std::optional<std::string> value;
  for (const auto& [k, v] : info.properties) {
    if (k != key) continue;
    if (value && *value != v)
      fail(path, "conflicting '" + std::string(key) + "' lines in the header: " + quoted(*value) + " and " + quoted(v));
    value = v;
  }
  return value;
}

// Samples are non-finite exactly when all exponent bits are set. `mask` is
// the exponent field as it lies in memory (byte-swapped for foreign order),
// so NaN/Inf are found without converting anything.
template <typename Word>
size_t findNonFiniteWords(const uint8_t* p, size_t n, Word mask) {
  size_t i = 0;
#if defined(__SSE2__)
  // 64 bytes per step: AND with the exponent mask and compare 32-bit lanes;
  // a 64-bit sample matches when both of its lanes do (its other lane of the
  // mask is zero, so it always compares equal). The exact index is found by
  // the scalar loop below, which starts in the step that has a hit.
  const __m128i m =
      sizeof(Word) == 4 ? _mm_set1_epi32(static_cast<int>(mask)) : _mm_set1_epi64x(static_cast<long long>(mask));
  constexpr size_t kStep = 64 / sizeof(Word);
  for (; i + kStep <= n; i += kStep) {
    const uint8_t* q = p + i * sizeof(Word);
    __m128i any = _mm_setzero_si128();
    for (int k = 0; k < 4; ++k) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q + 16 * k));
      __m128i eq = _mm_cmpeq_epi32(_mm_and_si128(v, m), m);
      if constexpr (sizeof(Word) == 8) eq = _mm_and_si128(eq, _mm_shuffle_epi32(eq, _MM_SHUFFLE(2, 3, 0, 1)));
      any = _mm_or_si128(any, eq);
    }
    if (_mm_movemask_epi8(any) != 0) break;
  }
#endif
  for (; i < n; ++i) {
    Word w;
    std::memcpy(&w, p + i * sizeof(Word), sizeof(Word));
    if ((w & mask) == mask) return i;
  }
  return n;
}

}  // namespace

std::optional<TckDataType> parseTckDataType(std::string_view name) {
  std::string lower(name);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == "float32le") return TckDataType{"Float32LE", 4, false};
  if (lower == "float32be") return TckDataType{"Float32BE", 4, true};
  if (lower == "float64le") return TckDataType{"Float64LE", 8, false};
  if (lower == "float64be") return TckDataType{"Float64BE", 8, true};
  return std::nullopt;
}

std::string printableExcerpt(std::string_view text, size_t max_chars) {
  std::string out;
  for (size_t i = 0; i < text.size() && i < max_chars; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    // Messages stay one line of plain ASCII whatever the file holds.
    out += (c < 0x20 || c >= 0x7f) ? '?' : static_cast<char>(c);
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

TckHeaderInfo parseTckHeader(const MappedFile& file, std::string_view magic) {
  const std::string& path = file.path();
  const std::string_view all = file.view();
  const bool want_tck = magic == kTckMagic;
  const char* what = want_tck ? ".tck" : ".tsf";
  if (all.empty())
    fail(path, std::string("empty file, expected a ") + what + " header starting with '" + std::string(magic) + "'");

  size_t cursor = 0;
  // Returns the next line without its '\n'; `terminated` is false for a
  // last line that runs to the end of the file.
  auto nextLine = [&](bool& terminated) {
    const size_t nl = all.find('\n', cursor);
    terminated = nl != std::string_view::npos;
    const size_t end = terminated ? nl : all.size();
    std::string_view line = all.substr(cursor, end - cursor);
    cursor = terminated ? nl + 1 : all.size();
    return line;
  };

  bool terminated = false;
  // MRtrix pads the first line with spaces (room to rewrite it in place).
  const std::string_view first = strip(nextLine(terminated));
  if (first != magic) {
    if (want_tck && first == kTsfMagic) fail(path, "is a track scalar file (.tsf), not a tractogram (.tck)");
    if (!want_tck && first == kTckMagic) fail(path, "is a tractogram (.tck), not a track scalar file (.tsf)");
    fail(path, std::string("not a ") + what + " file: first line is " + quoted(first) + ", expected '" +
                   std::string(magic) + "'");
  }

  TckHeaderInfo info;
  bool found_end = false;
  size_t line_number = 1;
  while (cursor < all.size()) {
    ++line_number;
    const std::string_view line = strip(nextLine(terminated));
    if (line == "END") {
      found_end = true;
      info.header_end = cursor;
      break;
    }
    if (line.empty()) continue;
    const size_t colon = line.find(':');
    const std::string_view key = colon == std::string_view::npos ? std::string_view() : strip(line.substr(0, colon));
    if (key.empty()) {
      info.warnings.push_back("header line " + std::to_string(line_number) + " " + quoted(line) +
                              " is not 'key: value'; ignored");
      continue;
    }
    info.properties.emplace_back(std::string(key), std::string(strip(line.substr(colon + 1))));
  }
  if (!found_end)
    fail(path, "header has no END line (the file ends at byte " + std::to_string(all.size()) + " inside the header)");

  const auto datatype = singleValue(path, info, "datatype");
  if (!datatype)
    fail(path,
         "no datatype specified (expected a 'datatype: Float32LE' line; Float32BE, Float64LE and Float64BE are "
         "also allowed)");
  const auto type = parseTckDataType(*datatype);
  if (!type)
    fail(path,
         "datatype " + quoted(*datatype) + " is not supported (expected Float32LE, Float32BE, Float64LE or Float64BE)");
  info.datatype = *type;

  const auto file_line = singleValue(path, info, "file");
  if (!file_line) fail(path, "no 'file: . OFFSET' line in the header, so the data cannot be located");
  {
    std::vector<std::string_view> tokens;
    std::string_view rest = *file_line;
    while (!(rest = strip(rest)).empty()) {
      const size_t sp = rest.find_first_of(" \t");
      tokens.push_back(rest.substr(0, sp));
      rest = sp == std::string_view::npos ? std::string_view() : rest.substr(sp);
    }
    if (tokens.empty() || tokens[0] != ".")
      fail(path, "file line " + quoted(*file_line) +
                     " names a separate data file, which is not supported (expected '. OFFSET': data in this file)");
    if (tokens.size() != 2 || !isAllDigits(tokens[1]))
      fail(path, "file line " + quoted(*file_line) + " is not '. OFFSET' with a byte offset");
    const auto offset = parseUnsigned(tokens[1]);
    if (!offset || *offset > all.size())
      fail(path, "data offset " + printableExcerpt(tokens[1], 30) + " is beyond the end of the file (" +
                     std::to_string(all.size()) + " bytes)");
    if (*offset < info.header_end)
      fail(path, "data offset " + std::to_string(*offset) + " lies inside the header, which ends at byte " +
                     std::to_string(info.header_end));
    info.data_offset = *offset;
  }

  for (const auto& [k, v] : info.properties) {
    if (k != "count") continue;
    const auto n = parseUnsigned(v);
    if (n && *n <= static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) {
      info.count = static_cast<int64_t>(*n);
    } else {
      info.count = -1;
      info.warnings.push_back("count " + quoted(v) + " is not a number; ignored");
    }
  }
  return info;
}

size_t findNonFinite(const uint8_t* p, size_t n, const TckDataType& type) {
  if (type.bytes == 4) {
    const uint32_t exponent = 0x7F800000u;
    return findNonFiniteWords<uint32_t>(p, n, type.needsSwap() ? byteSwap32(exponent) : exponent);
  }
  const uint64_t exponent = 0x7FF0000000000000ull;
  return findNonFiniteWords<uint64_t>(p, n, type.needsSwap() ? byteSwap64(exponent) : exponent);
}

SampleKind classifySample(const uint8_t* p, const TckDataType& type) {
  const double v =
      type.bytes == 4 ? double(loadUnaligned<float>(p, type.needsSwap())) : loadUnaligned<double>(p, type.needsSwap());
  if (std::isnan(v)) return SampleKind::kNaN;
  if (std::isinf(v)) return SampleKind::kInf;
  return SampleKind::kFinite;
}

void decodeSamples(const uint8_t* p, size_t n, const TckDataType& type, float* out, const std::string& path,
                   uint64_t file_offset) {
  const bool swap = type.needsSwap();
  if (type.bytes == 4) {
    if (!swap) {
      std::memcpy(out, p, n * 4);
      return;
    }
    for (size_t i = 0; i < n; ++i) out[i] = loadUnaligned<float>(p + 4 * i, true);
    return;
  }
  for (size_t i = 0; i < n; ++i) {
    const double v = loadUnaligned<double>(p + 8 * i, swap);
    // Converting a double beyond the float range is undefined behaviour.
    if (!(std::fabs(v) <= double(FLT_MAX)))
      failAt(path, file_offset + 8 * i, "sample " + std::to_string(v) + " does not fit in a 32-bit float");
    out[i] = static_cast<float>(v);
  }
}

void appendSamples(const uint8_t* p, size_t n, const TckDataType& type, std::vector<float>& out,
                   const std::string& path, uint64_t file_offset) {
  if (type.bytes == 4 && !type.needsSwap() && reinterpret_cast<uintptr_t>(p) % alignof(float) == 0) {
    // One bulk copy, without zero-filling the destination first.
    const auto* f = reinterpret_cast<const float*>(p);
    out.insert(out.end(), f, f + n);
    return;
  }
  const size_t old = out.size();
  out.resize(old + n);
  decodeSamples(p, n, type, out.data() + old, path, file_offset);
}

void encodeSamples(const float* values, size_t n, const TckDataType& type, std::vector<uint8_t>& out) {
  if (n == 0) return;  // `values` may be null for an empty streamline
  const size_t old = out.size();
  out.resize(old + n * type.bytes);
  uint8_t* dst = out.data() + old;
  const bool swap = type.needsSwap();
  if (type.bytes == 4) {
    if (!swap) {
      std::memcpy(dst, values, n * 4);
      return;
    }
    for (size_t i = 0; i < n; ++i) storeUnaligned<float>(dst + 4 * i, values[i], true);
    return;
  }
  for (size_t i = 0; i < n; ++i) storeUnaligned<double>(dst + 8 * i, double(values[i]), swap);
}

void encodeRepeated(float value, size_t n, const TckDataType& type, std::vector<uint8_t>& out) {
  for (size_t i = 0; i < n; ++i) encodeSamples(&value, 1, type, out);
}

TrackDataStream::TrackDataStream(const std::string& path, uint64_t begin, uint64_t end)
    : path_(path), next_(begin), end_(end) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) failErrno(path, "cannot open");
  ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
  // 1 MiB: big enough that syscalls cost nothing, small enough to stay in L2.
  // Small files get a buffer of their size (then ASan sees any overread).
  const uint64_t bytes = std::clamp<uint64_t>(end > begin ? end - begin : 0, 64, uint64_t(1) << 20);
  buffer_.resize(static_cast<size_t>((bytes + sizeof(float) - 1) / sizeof(float)));
  capacity_ = buffer_.size() * sizeof(float);
}

TrackDataStream::~TrackDataStream() {
  if (fd_ >= 0) ::close(fd_);
}

size_t TrackDataStream::fill(size_t n) {
  if (available() >= n || next_ >= end_) return available();
  // Keep the unread tail, moved to the front (less than a streamline's worth).
  std::memmove(bytes(), bytes() + head_, available());
  tail_ -= head_;
  head_ = 0;
  // Up to the soft end as much as fits; past it only what was asked for.
  while (tail_ < capacity_ && next_ < end_ && (next_ < soft_end_ || tail_ - head_ < n)) {
    const uint64_t until = std::min(end_, next_ < soft_end_ ? soft_end_ : next_ + kPastSoftEnd);
    const size_t want = static_cast<size_t>(std::min<uint64_t>(capacity_ - tail_, until - next_));
    const ssize_t got = ::pread(fd_, bytes() + tail_, want, static_cast<off_t>(next_));
    if (got < 0) {
      if (errno == EINTR) continue;
      failErrno(path_, "read failed at byte " + std::to_string(next_));
    }
    if (got == 0) {
      // The file shrank since it was opened: treat what is there as all.
      end_ = next_;
      break;
    }
    tail_ += static_cast<size_t>(got);
    next_ += static_cast<uint64_t>(got);
  }
  return available();
}

std::optional<std::string> tckCountWarning(bool has_count_line, int64_t header_count, uint64_t streamlines) {
  const std::string holds = " the file holds " + std::to_string(streamlines) + " streamlines";
  if (!has_count_line) return "header has no count;" + holds;
  if (header_count >= 0 && static_cast<uint64_t>(header_count) != streamlines)
    return "header says count " + std::to_string(header_count) + " but" + holds;
  return std::nullopt;
}

bool isTckWriterOwnedKey(std::string_view key) {
  return key == "datatype" || key == "file" || key == "count" || key == "total_count" || key == "END";
}

std::string formatTckCount(uint64_t count) {
  char digits[32];
  std::snprintf(digits, sizeof digits, "%0*llu", int(TckHeaderText::kCountDigits),
                static_cast<unsigned long long>(count));
  return digits;
}

TckHeaderText makeTckHeader(std::string_view magic, const std::vector<std::pair<std::string, std::string>>& properties,
                            const TckDataType& type, std::vector<std::string>* dropped) {
  TckHeaderText out;
  std::string& h = out.text;
  h.append(magic).append("\n");
  for (const auto& [key, value] : properties) {
    if (isTckWriterOwnedKey(key)) continue;
    // The reader splits at the first ':' and strips blanks, so such keys
    // would come back as something else.
    const bool unwritable = key.empty() || key.find_first_of(":\n\r") != std::string::npos || strip(key) != key;
    if (unwritable) {
      if (dropped)
        dropped->push_back("header key " + quoted(key) + " cannot be stored in a track file header; dropped");
      continue;
    }
    // MRtrix joins repeated keys with newlines; write them back as repeats.
    size_t begin = 0;
    while (true) {
      const size_t nl = value.find('\n', begin);
      const std::string_view line =
          strip(std::string_view(value).substr(begin, nl == std::string::npos ? nl : nl - begin));
      h.append(key).append(": ").append(line).append("\n");
      if (nl == std::string::npos) break;
      begin = nl + 1;
    }
  }
  h.append("datatype: ").append(type.name).append("\n");
  h.append("count: ");
  out.count_offset = h.size();
  h.append(formatTckCount(0)).append("\n");
  // The offset counts its own digits: grow the digit count until stable.
  const size_t base = h.size() + std::strlen("file: . ") + std::strlen("\nEND\n");
  size_t digits = 1;
  while (std::to_string(base + digits).size() != digits) ++digits;
  h.append("file: . ").append(std::to_string(base + digits)).append("\nEND\n");
  return out;
}

}  // namespace fibscope
