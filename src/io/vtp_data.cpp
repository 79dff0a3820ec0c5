// VTK XML DataArray contents: base64, block headers, zlib / LZ4 / LZMA.
#include "io/vtp_data.h"

#include <lz4.h>
#include <lzma.h>
#include <zlib.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstring>

#include "core/byte_order.h"
#include "core/error.h"

namespace fibscope::vtp {
namespace {

// Block sizes above this are not something VTK writes (its default is
// 32 KiB); refusing them bounds the memory one lying header can claim.
constexpr uint64_t kMaxBlockBytes = uint64_t(1) << 30;

bool isSpace(uint8_t c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v'; }

int base64Value(uint8_t c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

// Hands out the bytes of a BinarySource in order: raw bytes as they are,
// base64 decoded a 4-character group at a time (see vtp_data.h).
class ByteStream {
 public:
  ByteStream(const BinarySource& s, const std::string& path, const std::string& what)
      : s_(s), path_(path), what_(what) {}

  // An upper bound of the bytes still to come (before any allocation).
  uint64_t bound() const {
    return (s_.base64 ? (s_.size - pos_) / 4 * 3 + 3 : s_.size - pos_) + (pending_n_ - pending_at_);
  }

  void read(uint8_t* out, uint64_t n, const char* part) {
    if (n == 0) return;  // an empty array: `out` may be null
    if (!s_.base64) {
      if (n > s_.size - pos_) fail(part, "ends " + std::to_string(n - (s_.size - pos_)) + " bytes early");
      std::memcpy(out, s_.data + pos_, n);
      pos_ += n;
      return;
    }
    while (n > 0) {
      if (pending_at_ == pending_n_) decodeGroup(part);
      const uint64_t take = std::min<uint64_t>(n, pending_n_ - pending_at_);
      std::memcpy(out, pending_.data() + pending_at_, take);
      pending_at_ += uint32_t(take);
      out += take;
      n -= take;
    }
  }
  uint64_t offset() const { return s_.offset + pos_; }

  [[noreturn]] void fail(const char* part, const std::string& message) const {
    failAt(path_, offset(), what_ + ": " + part + " " + message);
  }

 private:
  void decodeGroup(const char* part) {
    std::array<int, 4> v{};
    int got = 0, pad = 0;
    while (got < 4) {
      while (pos_ < s_.size && isSpace(s_.data[pos_])) ++pos_;
      if (pos_ >= s_.size || s_.data[pos_] == '<') fail(part, "ends early (the base64 text is too short)");
      const uint8_t c = s_.data[pos_];
      if (c == '=') {
        if (got < 2) fail(part, "has '=' padding inside a base64 group");
        ++pad;
        v[got++] = 0;
      } else {
        const int d = base64Value(c);
        if (d < 0) fail(part, "holds a byte that is not base64 (" + std::to_string(int(c)) + ")");
        if (pad > 0) fail(part, "has base64 data after '=' padding in one group");
        v[got++] = d;
      }
      ++pos_;
    }
    const uint32_t bits = uint32_t(v[0]) << 18 | uint32_t(v[1]) << 12 | uint32_t(v[2]) << 6 | uint32_t(v[3]);
    pending_ = {uint8_t(bits >> 16), uint8_t(bits >> 8), uint8_t(bits)};
    pending_n_ = uint32_t(3 - pad);
    pending_at_ = 0;
  }

  const BinarySource& s_;
  const std::string& path_;
  const std::string& what_;
  uint64_t pos_ = 0;
  std::array<uint8_t, 3> pending_{};
  uint32_t pending_n_ = 0, pending_at_ = 0;
};

uint64_t headerWord(ByteStream& in, const Encoding& e, const char* part) {
  uint8_t b[8] = {};
  in.read(b, e.header_bytes, part);
  return e.header_bytes == 8 ? loadUnaligned<uint64_t>(b, e.swap) : loadUnaligned<uint32_t>(b, e.swap);
}

// Decompresses one block into exactly `out_size` bytes; false when the
// block is corrupt or of another size.
bool inflateBlock(Compressor c, const uint8_t* in, uint64_t in_size, uint8_t* out, uint64_t out_size) {
  switch (c) {
    case Compressor::kZlib: {
      uLongf n = uLongf(out_size);
      return uncompress(out, &n, in, uLong(in_size)) == Z_OK && n == out_size;
    }
    case Compressor::kLz4: {
      if (in_size > uint64_t(INT32_MAX) || out_size > uint64_t(INT32_MAX)) return false;
      return LZ4_decompress_safe(reinterpret_cast<const char*>(in), reinterpret_cast<char*>(out), int(in_size),
                                 int(out_size)) == int(out_size);
    }
    case Compressor::kLzma: {
      uint64_t memlimit = uint64_t(1) << 30;
      size_t in_pos = 0, out_pos = 0;
      return lzma_stream_buffer_decode(&memlimit, 0, nullptr, in, &in_pos, size_t(in_size), out, &out_pos,
                                       size_t(out_size)) == LZMA_OK &&
             out_pos == out_size && in_pos == in_size;
    }
    case Compressor::kNone: break;
  }
  return false;
}

}  // namespace

std::optional<Type> typeNamed(std::string_view n) {
  static constexpr std::pair<std::string_view, Type> kNames[] = {
      {"Int8", Type::kInt8},       {"UInt8", Type::kUInt8},     {"Int16", Type::kInt16},   {"UInt16", Type::kUInt16},
      {"Int32", Type::kInt32},     {"UInt32", Type::kUInt32},   {"Int64", Type::kInt64},   {"UInt64", Type::kUInt64},
      {"Float32", Type::kFloat32}, {"Float64", Type::kFloat64}, {"String", Type::kString}, {"Bit", Type::kBit}};
  for (const auto& [name, type] : kNames)
    if (name == n) return type;
  return std::nullopt;
}

uint32_t typeBytes(Type t) {
  switch (t) {
    case Type::kInt16: case Type::kUInt16: return 2;
    case Type::kInt32: case Type::kUInt32: case Type::kFloat32: return 4;
    case Type::kInt64: case Type::kUInt64: case Type::kFloat64: return 8;
    default: return 1;
  }
}

const char* dtypeName(Type t) {
  static const char* kNames[] = {"int8",  "uint8",   "int16",   "uint16", "int32", "uint32",
                                 "int64", "uint64", "float32", "float64", "string", "bit"};
  return kNames[int(t)];
}

double valueAt(const uint8_t* bytes, Type t, bool swap, uint64_t i) {
  const uint8_t* p = bytes + i * typeBytes(t);
  switch (t) {
    case Type::kInt8: return double(static_cast<int8_t>(*p));
    case Type::kUInt8: return double(*p);
    case Type::kInt16: return double(loadUnaligned<int16_t>(p, swap));
    case Type::kUInt16: return double(loadUnaligned<uint16_t>(p, swap));
    case Type::kInt32: return double(loadUnaligned<int32_t>(p, swap));
    case Type::kUInt32: return double(loadUnaligned<uint32_t>(p, swap));
    case Type::kInt64: return double(loadUnaligned<int64_t>(p, swap));
    case Type::kUInt64: return double(loadUnaligned<uint64_t>(p, swap));
    case Type::kFloat32: return double(loadUnaligned<float>(p, swap));
    case Type::kFloat64: return loadUnaligned<double>(p, swap);
    default: return double(*p);
  }
}

std::vector<uint8_t> decodeBinary(const Encoding& e, const BinarySource& source, std::optional<uint64_t> expected,
                                  uint64_t max_bytes, const std::string& path, const std::string& what) {
  ByteStream in(source, path, what);
  std::vector<uint8_t> out;
  auto checkTotal = [&](uint64_t total) {
    if (expected && total != *expected)
      in.fail("header", "says " + std::to_string(total) + " bytes, its tuples need " + std::to_string(*expected));
    if (total > max_bytes) in.fail("header", "says " + std::to_string(total) + " bytes, more than allowed here");
  };
  if (e.compressor == Compressor::kNone) {
    const uint64_t n = headerWord(in, e, "header");
    checkTotal(n);
    if (n > in.bound()) in.fail("data", "needs " + std::to_string(n) + " bytes, more than remain");
    out.resize(n);
    in.read(out.data(), n, "data");
    return out;
  }
  const uint64_t blocks = headerWord(in, e, "header");
  if (blocks > in.bound() / e.header_bytes)
    in.fail("header", "says " + std::to_string(blocks) + " compressed blocks, more than the bytes that remain");
  const uint64_t block_size = headerWord(in, e, "header");
  const uint64_t last_size = headerWord(in, e, "header");
  if (blocks > 0 && (block_size == 0 || block_size > kMaxBlockBytes || last_size > block_size))
    in.fail("header", "has block size " + std::to_string(block_size) + " and last block size " +
                          std::to_string(last_size));
  std::vector<uint64_t> sizes(blocks);
  uint64_t compressed = 0;
  for (auto& s : sizes) {
    s = headerWord(in, e, "header");
    if (s > in.bound()) in.fail("header", "says a block of " + std::to_string(s) + " bytes, more than remain");
    compressed += s;
  }
  if (compressed > in.bound()) in.fail("data", "blocks need " + std::to_string(compressed) + " bytes, more than remain");
  const uint64_t total = blocks == 0 ? 0 : (blocks - 1) * block_size + (last_size ? last_size : block_size);
  checkTotal(total);
  if (total > compressed * kMaxExpansion + (uint64_t(1) << 20))
    in.fail("header", "says " + std::to_string(compressed) + " compressed bytes expand to " + std::to_string(total) +
                          ", more than " + std::to_string(kMaxExpansion) + "-fold");
  out.resize(total);
  std::vector<uint8_t> block;
  uint64_t at = 0;
  for (uint64_t b = 0; b < blocks; ++b) {
    const uint64_t start = in.offset();
    block.resize(sizes[b]);
    in.read(block.data(), sizes[b], "data");
    const uint64_t n = b + 1 == blocks && last_size ? last_size : block_size;
    if (!inflateBlock(e.compressor, block.data(), sizes[b], out.data() + at, n))
      failAt(path, start, what + ": compressed block " + std::to_string(b) + " of " + std::to_string(blocks) +
                              " is corrupt (it does not decompress to " + std::to_string(n) + " bytes)");
    at += n;
  }
  return out;
}

std::vector<double> parseAscii(std::string_view text, Type type, std::optional<uint64_t> count, uint64_t max_count,
                               uint64_t offset, const std::string& path, const std::string& what) {
  std::vector<double> values;
  // Every value takes two bytes at least (a digit and a separator, but the
  // last): a bound before any allocation.
  const uint64_t bound = text.size() / 2 + 1;
  if (count && *count > bound)
    failAt(path, offset, what + ": " + std::to_string(*count) + " ASCII values cannot fit in " +
                             std::to_string(text.size()) + " bytes");
  values.reserve(count ? *count : std::min<uint64_t>(bound, max_count));
  size_t i = 0;
  const bool integral = isIntegral(type) || type == Type::kString;
  while (true) {
    while (i < text.size() && isSpace(uint8_t(text[i]))) ++i;
    if (i >= text.size()) break;
    size_t j = i;
    while (j < text.size() && !isSpace(uint8_t(text[j]))) ++j;
    const std::string_view word = text.substr(i, j - i);
    double v = 0;
    bool ok = false;
    if (integral) {
      int64_t n = 0;
      std::string_view w = word;
      if (w.size() > 1 && w[0] == '+') w.remove_prefix(1);
      const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), n);
      ok = ec == std::errc() && end == w.data() + w.size();
      if (!ok && type == Type::kUInt64) {
        uint64_t u = 0;
        const auto [end2, ec2] = std::from_chars(w.data(), w.data() + w.size(), u);
        ok = ec2 == std::errc() && end2 == w.data() + w.size();
        v = double(u);
      } else {
        v = double(n);
      }
    } else {
      const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
      ok = ec == std::errc() && end == word.data() + word.size();
    }
    if (!ok) {
      std::string shown(word.substr(0, 40));
      for (char& c : shown)
        if (uint8_t(c) < 0x20 || uint8_t(c) >= 0x7f) c = '?';
      failAt(path, offset + i, what + ": '" + shown + "' is not " + (integral ? "an integer" : "a number"));
    }
    if ((count && values.size() == *count) || (!count && values.size() == max_count))
      failAt(path, offset + i, what + ": more ASCII values than the " +
                                   std::to_string(count ? *count : max_count) + " it should hold");
    values.push_back(v);
    i = j;
  }
  if (count && values.size() != *count)
    failAt(path, offset, what + ": " + std::to_string(values.size()) + " ASCII values, expected " +
                             std::to_string(*count));
  return values;
}

}  // namespace fibscope::vtp
