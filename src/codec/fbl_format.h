// On-disk layout of a .fbl file (docs/FBL_FORMAT.md is the prose version).
//
// All integers and floats are little-endian and stored at the explicit byte
// offsets below; readers and writers go through load/storeUnaligned rather
// than packed structs, so the layout does not depend on compiler padding.
//
//   [0, 256)                 header (kFblHeaderBytes)
//   [256, 256 + 96 * cap)    section table: section_count entries used, the
//                            rest of the reserved capacity zero
//   64-byte aligned          section data, in table order, each followed by
//                            zero padding to the next multiple of 64
//   file_bytes               end of file (a multiple of 64)
#pragma once

#include <cstddef>
#include <cstdint>

namespace fibscope::fbl {

inline constexpr char kMagic[8] = {'F', 'I', 'B', 'L', 'E', 'T', 'S', '\0'};
inline constexpr uint32_t kFormatVersion = 1;
inline constexpr uint32_t kHeaderBytes = 256;
inline constexpr uint32_t kSectionEntryBytes = 96;
inline constexpr uint32_t kSectionNameBytes = 48;  // NUL-padded, at most 47 bytes of name
inline constexpr uint64_t kAlignment = 64;         // every section offset and the file size

// Header field offsets. Every future version keeps magic, version and
// header_bytes where they are and the header checksum in the last 4 bytes of
// the header, so an old reader can tell "newer file" from "corrupt file".
namespace header {
inline constexpr size_t kMagic = 0;                // char[8] "FIBLETS\0"
inline constexpr size_t kVersion = 8;              // u32
inline constexpr size_t kHeaderBytes = 12;         // u32, 256
inline constexpr size_t kFlags = 16;               // u32, 0 in version 1
inline constexpr size_t kCodecVersion = 20;        // u32, version of the fiblet encoding
inline constexpr size_t kFiberCount = 24;          // u64
inline constexpr size_t kFibletCount = 32;         // u64
inline constexpr size_t kPointCount = 40;          // u64
inline constexpr size_t kPointsPerFiblet = 48;     // u32, N
inline constexpr size_t kFibletRecordBytes = 52;   // u32
inline constexpr size_t kTranslation = 56;         // f64[3]
inline constexpr size_t kScale = 80;               // f64
inline constexpr size_t kDelta = 88;               // f64, normalised units
inline constexpr size_t kDeltaMm = 96;             // f64
inline constexpr size_t kAlpha = 104;              // f64, radians
inline constexpr size_t kV = 112;                  // f32[3]
inline constexpr size_t kSectionCount = 124;       // u32
inline constexpr size_t kTableOffset = 128;        // u64, 256
inline constexpr size_t kTableCapacity = 136;      // u32, entries reserved
inline constexpr size_t kTableChecksum = 140;      // u32, CRC-32C of the used entries
inline constexpr size_t kFileBytes = 144;          // u64
inline constexpr size_t kReserved = 152;           // zero up to the checksum
inline constexpr size_t kHeaderChecksum = 252;     // u32, CRC-32C of bytes [0, 252)
}  // namespace header

// Section table entry field offsets (relative to the entry).
namespace entry {
inline constexpr size_t kName = 0;          // char[48]
inline constexpr size_t kDType = 48;        // u32, FblDType
inline constexpr size_t kComponents = 52;   // u32, >= 1
inline constexpr size_t kElementCount = 56; // u64
inline constexpr size_t kOffset = 64;       // u64, multiple of 64
inline constexpr size_t kBytes = 72;        // u64 = element_count * components * dtype size
inline constexpr size_t kChecksum = 80;     // u32, CRC-32C of the section's bytes
inline constexpr size_t kReserved = 84;     // 12 zero bytes
}  // namespace entry

static_assert(header::kHeaderChecksum + 4 == kHeaderBytes);
static_assert(entry::kReserved + 12 == kSectionEntryBytes);
static_assert(kHeaderBytes % kAlignment == 0);

}  // namespace fibscope::fbl
