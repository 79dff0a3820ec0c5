// Endianness helpers for binary formats (tck Float32BE, trk big-endian, ...).
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

namespace fibscope {

inline uint16_t byteSwap16(uint16_t v) { return static_cast<uint16_t>((v >> 8) | (v << 8)); }
inline uint32_t byteSwap32(uint32_t v) { return __builtin_bswap32(v); }
inline uint64_t byteSwap64(uint64_t v) { return __builtin_bswap64(v); }

// Reads a T from unaligned memory, swapping bytes when `swap`.
template <typename T>
inline T loadUnaligned(const void* p, bool swap = false) {
  static_assert(sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4 || sizeof(T) == 8);
  T v;
  std::memcpy(&v, p, sizeof(T));
  if (swap) {
    if constexpr (sizeof(T) == 2) v = std::bit_cast<T>(byteSwap16(std::bit_cast<uint16_t>(v)));
    if constexpr (sizeof(T) == 4) v = std::bit_cast<T>(byteSwap32(std::bit_cast<uint32_t>(v)));
    if constexpr (sizeof(T) == 8) v = std::bit_cast<T>(byteSwap64(std::bit_cast<uint64_t>(v)));
  }
  return v;
}

template <typename T>
inline void storeUnaligned(void* p, T v, bool swap = false) {
  if (swap) {
    if constexpr (sizeof(T) == 2) v = std::bit_cast<T>(byteSwap16(std::bit_cast<uint16_t>(v)));
    if constexpr (sizeof(T) == 4) v = std::bit_cast<T>(byteSwap32(std::bit_cast<uint32_t>(v)));
    if constexpr (sizeof(T) == 8) v = std::bit_cast<T>(byteSwap64(std::bit_cast<uint64_t>(v)));
  }
  std::memcpy(p, &v, sizeof(T));
}

constexpr bool kHostIsLittleEndian = std::endian::native == std::endian::little;

}  // namespace fibscope
