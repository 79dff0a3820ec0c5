// Reading a .fbl file as a tractogram: the fiblets decoded chunk by chunk
// back into streamlines in world mm, behind the TractogramReader interface
// that every command and the viewer's loader already use.
#pragma once

#include <memory>
#include <string>

#include "codec/fiblet_decoder.h"
#include "io/reader.h"

namespace fibscope {

// The most points one decoded fiber may have. A fiblet record of N + 11
// bytes expands to up to N points of 12 bytes each (about 10x), so one
// fiber spanning a large file would otherwise be an unbounded allocation;
// 2^24 points is 1,600 m of fiber at a 0.1 mm step, far beyond any tracker.
inline constexpr uint64_t kFblMaxFiberPoints = uint64_t(1) << 24;

// Opens a .fbl file written by `fibscope compress` (docs/FBL_FORMAT.md):
// fiblet records in "fiblets", "fiber_first_fiblet", per-fiber "dps/<name>"
// arrays and the "source" JSON.
//
// header(): format, space, properties, per-streamline and per-point arrays
// of the original file (from "source"), path = `path`, file_bytes = the
// .fbl's size, declared_streamlines / declared_points = the header's fiber
// and point counts. Per-point arrays ("dpv/<name>", one value per encoded
// point: resampled with the points when the file was) come with the
// "fiber_first_point" table, whose entries must match the decoded counts.
//
// read() decodes whole fibers, about max_points points a chunk, in `order`
// (by default Sequential: the points the compression report measured, and
// 5x cheaper than the GPU's Scan order) and toWorld rounded to float, so the
// points equal FibletDecoder::decodeAll(records, order) bit for bit
// whatever the chunk size. Memory is bounded by the chunk (the records
// stay in the read-only map).
//
// Safe on untrusted files. On open: the container checks (FblFile::open),
// every section's checksum, the codec parameters, the "source" JSON, that
// every dps section is listed in it with the same components and vice
// versa, and the first-fiblet table's ends. While reading, per fiber: the
// table increasing and within the fiblets, each fiblet's point count in
// [1, N], the begins/ends flags exactly on the fiber's first/last fiblet;
// after the last fiber, the header's point count equals the points decoded.
// Every problem is a one-line Error naming the path and the section, fiber
// or fiblet index. bytesRead() advances with the fiblets consumed.
std::unique_ptr<TractogramReader> openFbl(const std::string& path, DecodeOrder order = DecodeOrder::Sequential);

}  // namespace fibscope
