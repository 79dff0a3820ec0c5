// CRC-32C (Castagnoli), the checksum of every .fbl section.
//
// Polynomial 0x1EDC6F41 (reflected 0x82F63B78), initial value and final XOR
// 0xFFFFFFFF, bytes processed LSB first: the CRC of iSCSI (RFC 3720), ext4
// and Btrfs. Check value: crc32c("123456789") = 0xE3069283. Chosen because
// x86-64 computes it in hardware (SSE4.2 crc32 instruction, ~10+ GB/s per
// core), so verifying a multi-gigabyte fiblet section costs less than reading
// it; elsewhere a slicing-by-8 table version runs at ~1-2 GB/s.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fibscope {

// Continues a CRC-32C: crc32c(b, crc32c(a)) == crc32c(a followed by b).
// Start with crc = 0 (the empty message). Safe on any bytes; `data` may be
// null when `bytes` is 0.
uint32_t crc32c(const void* data, size_t bytes, uint32_t crc = 0);

// The table-driven version, whatever the CPU (tests compare both paths).
uint32_t crc32cPortable(const void* data, size_t bytes, uint32_t crc = 0);

// True when crc32c() uses the CPU's crc32 instruction (for benchmarks/logs).
bool crc32cIsHardware();

}  // namespace fibscope
