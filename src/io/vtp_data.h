// The contents of one VTK XML <DataArray>: ASCII numbers, or binary bytes
// (inline base64, or in the file's <AppendedData> as raw bytes or base64),
// each binary block preceded by its header: one size word when
// uncompressed; block count, block size, last block's size and each block's
// compressed size when compressed (zlib, LZ4 or LZMA, as VTK's three
// compressors write them). Header words are UInt32 or UInt64
// (VTKFile header_type) in the file's byte order.
//
// Base64 is decoded as one stream of 4-character groups, each yielding the
// bytes its padding leaves: VTK encodes a compressed array's header and its
// blocks separately (padded apart), an uncompressed one together, and both
// read the same way here.
//
// Every size is checked against the bytes that can still be decoded before
// anything is allocated; a claim of expanding more than kMaxExpansion-fold
// under compression is refused as malformed (real data expands ~2-10x).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fibscope::vtp {

enum class Type { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kInt64, kUInt64, kFloat32, kFloat64, kString, kBit };

// "Int8" ... "Float64", "String", "Bit" (VTK XML type names; also the
// legacy aliases "Char", "UInt", ... are not XML and not accepted).
std::optional<Type> typeNamed(std::string_view name);
// Bytes of one value; 1 for String (characters) and Bit (packed, not read).
uint32_t typeBytes(Type type);
const char* dtypeName(Type type);  // fibscope's DataArray dtype ("float32", ...)
inline bool isNumeric(Type t) { return t != Type::kString && t != Type::kBit; }
inline bool isIntegral(Type t) { return isNumeric(t) && t != Type::kFloat32 && t != Type::kFloat64; }

enum class Compressor { kNone, kZlib, kLz4, kLzma };

struct Encoding {
  bool swap = false;           // the file's byte order is not the host's
  uint32_t header_bytes = 4;   // UInt32 or UInt64 header words
  Compressor compressor = Compressor::kNone;
};

constexpr uint64_t kMaxExpansion = 4096;

// Where a binary array's bytes are: `size` bytes of file text starting at
// `data` (file offset `offset`), base64 or raw.
struct BinarySource {
  const uint8_t* data = nullptr;
  uint64_t size = 0;
  uint64_t offset = 0;
  bool base64 = false;
};

// Decodes a binary array into its bytes (in the file's byte order).
// `expected` is the exact byte count the array must hold (from its tuple
// count), or empty where the header alone says (strings), then at most
// `max_bytes`. Throws Error "PATH: byte OFFSET: WHAT: ..." when malformed.
std::vector<uint8_t> decodeBinary(const Encoding& encoding, const BinarySource& source,
                                  std::optional<uint64_t> expected, uint64_t max_bytes, const std::string& path,
                                  const std::string& what);

// Parses `count` ASCII values of `type` (whitespace separated) into
// doubles; integer types are parsed as integers (exact up to 2^53), so a
// value such as 1.5 in an Int32 array is an error. `count` empty: all that
// are there, at most `max_count`.
std::vector<double> parseAscii(std::string_view text, Type type, std::optional<uint64_t> count, uint64_t max_count,
                               uint64_t offset, const std::string& path, const std::string& what);

// Value i of a decoded binary array.
double valueAt(const uint8_t* bytes, Type type, bool swap, uint64_t i);

}  // namespace fibscope::vtp
