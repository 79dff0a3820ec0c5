// libFuzzer target for the .fbl container reader and the fiblet reader on
// top of it (openFbl).
//
// Each input is opened twice: as given, and "repaired", i.e. with the header,
// section table and section checksums recomputed, so that mutations get past
// the CRCs and reach the structural checks (offsets, sizes, overlaps, counts).
// Only fibscope::Error is an accepted outcome. Whatever open() accepts must
// keep its promises: every section inside the file, 64-byte aligned, in order
// without overlap, and readable in full. A file the container accepts is
// then decoded streamline by streamline through openFbl (codec parameters,
// source JSON, dps sections, first-fiblet table and record flags); every
// chunk must keep the Tractogram invariants and agree with the header.
//
// Seeds: fuzz/seeds/fbl.py (container samples) and fuzz/seeds/fbl_fiblets.py
// (valid fiblet tractograms).
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "codec/fbl_file.h"
#include "codec/fbl_format.h"
#include "codec/fbl_reader.h"
#include "core/byte_order.h"
#include "core/checksum.h"
#include "core/error.h"
#include "fuzz_support.h"

namespace {

namespace fbl = fibscope::fbl;

// Every streamline through openFbl, in small chunks so that chunk
// boundaries are exercised too.
void decodeAll(const std::string& path) {
  try {
    auto reader = fibscope::openFbl(path);
    const fibscope::TractogramHeader& h = reader->header();
    if (h.declared_streamlines < 0 || h.declared_points < 0 || !h.per_point.empty()) std::abort();
    fibscope::Tractogram chunk;
    uint64_t streamlines = 0, points = 0;
    while (reader->read(chunk, 64)) {
      fibscope::fuzz::checkChunk(*reader, chunk);
      if (chunk.per_streamline.size() != h.per_streamline.size()) std::abort();
      for (size_t a = 0; a < chunk.per_streamline.size(); ++a)
        if (chunk.per_streamline[a].values.size() != chunk.streamlineCount() * h.per_streamline[a].components)
          std::abort();
      streamlines += chunk.streamlineCount();
      points += chunk.pointCount();
    }
    // A file read to the end without an error matches its header.
    if (streamlines != uint64_t(h.declared_streamlines) || points != uint64_t(h.declared_points)) std::abort();
    if (reader->bytesRead() != h.file_bytes) std::abort();
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
  }
}

void readAll(const std::string& path) {
  try {
    const fibscope::FblFile f = fibscope::FblFile::open(path);
    uint64_t previous_end = 0;
    for (const fibscope::FblSection& s : f.sections()) {
      if (s.offset % fbl::kAlignment != 0 || s.offset < previous_end) std::abort();
      if (s.offset > f.fileBytes() || s.bytes > f.fileBytes() - s.offset) std::abort();
      previous_end = s.offset + s.bytes;
      if (f.find(s.name) != &s) std::abort();
    }
    f.verify();
    volatile uint8_t sink = 0;
    for (const fibscope::FblSection& s : f.sections()) {
      const auto bytes = f.data(s);
      if (bytes.size() != s.bytes) std::abort();
      for (const uint8_t b : bytes) sink = sink ^ b;
      if (s.dtype == fibscope::FblDType::kFloat64) {
        for (const double v : f.array<double>(s)) sink = sink ^ static_cast<uint8_t>(v == v);
      }
    }
    decodeAll(path);
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
  }
}

// Recomputes every checksum that the bytes allow locating; leaves anything
// out of range alone (the reader must then reject it).
void repair(std::vector<uint8_t>& b) {
  if (b.size() < fbl::kHeaderBytes) return;
  uint8_t* p = b.data();
  const uint32_t count = fibscope::loadUnaligned<uint32_t>(p + fbl::header::kSectionCount);
  const uint64_t table_bytes = uint64_t(count) * fbl::kSectionEntryBytes;
  if (table_bytes <= b.size() - fbl::kHeaderBytes) {
    for (uint32_t i = 0; i < count; ++i) {
      uint8_t* e = p + fbl::kHeaderBytes + uint64_t(i) * fbl::kSectionEntryBytes;
      const uint64_t offset = fibscope::loadUnaligned<uint64_t>(e + fbl::entry::kOffset);
      const uint64_t bytes = fibscope::loadUnaligned<uint64_t>(e + fbl::entry::kBytes);
      if (offset <= b.size() && bytes <= b.size() - offset)
        fibscope::storeUnaligned<uint32_t>(e + fbl::entry::kChecksum, fibscope::crc32c(p + offset, bytes));
    }
    fibscope::storeUnaligned<uint32_t>(p + fbl::header::kTableChecksum,
                                       fibscope::crc32c(p + fbl::kHeaderBytes, table_bytes));
  }
  fibscope::storeUnaligned<uint32_t>(p + fbl::header::kHeaderChecksum, fibscope::crc32c(p, fbl::header::kHeaderChecksum));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = fibscope::fuzz::scratchPath("fbl", "input.fbl");
  fibscope::fuzz::writeInput(path, data, size);
  readAll(path);
  std::vector<uint8_t> repaired(data, data + size);
  repair(repaired);
  fibscope::fuzz::writeInput(path, repaired.data(), repaired.size());
  readAll(path);
  std::remove(path.c_str());
  return 0;
}
