// libFuzzer target for the TrackVis .trk reader (and a writer round trip).
//
// Each input is read twice: as given, and zero-padded to whole pages so that
// the data ends on a page boundary and a read past the end of the map
// faults (ASan does not watch mapped files). When an input reads without
// error, its streamlines are written with the trk writer and read back; the
// structure must survive. And once gzip-compressed (a .trk.gz, read through
// a window on the decompressed bytes): it must read exactly as the plain
// file, the same streamlines and warnings, or fail where that fails. Only
// fibscope::Error is an accepted outcome.
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/reader.h"
#include "fuzz_support.h"
#include "io/writer.h"

namespace {

struct Paths {
  std::string input, padded, output, gz;
};

const Paths& paths() {
  static const Paths p = [] {
    auto prefix = [](const std::string& name) { return fibscope::fuzz::scratchPath("trk", name); };
    return Paths{prefix("input.trk"), prefix("padded.trk"), prefix("output.trk"), prefix("input.trk.gz")};
  }();
  return p;
}

// The input as a gzip file (deflate at level 1 with the gzip wrapper).
void writeGzip(const std::string& path, const uint8_t* data, size_t size) {
  z_stream z{};
  if (deflateInit2(&z, 1, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) std::abort();
  std::vector<uint8_t> out(deflateBound(&z, uLong(size)) + 32);
  z.next_in = const_cast<Bytef*>(data);
  z.avail_in = uInt(size);
  z.next_out = out.data();
  z.avail_out = uInt(out.size());
  if (deflate(&z, Z_FINISH) != Z_STREAM_END) std::abort();
  fibscope::fuzz::writeInput(path, out.data(), z.total_out);
  deflateEnd(&z);
}

// Reads the whole file; returns false on Error.
bool readAll(const std::string& path, fibscope::Tractogram* all, fibscope::TractogramHeader* header,
             std::vector<std::string>* warnings = nullptr) {
  try {
    auto reader = fibscope::openTrk(path);
    fibscope::Tractogram chunk;
    while (reader->read(chunk, 16)) {
      if (!chunk.validate().empty() || chunk.streamlineCount() == 0) std::abort();
      if (reader->bytesRead() > reader->header().file_bytes) std::abort();
      if (all) all->append(chunk);
    }
    if (header) *header = reader->header();
    if (warnings) *warnings = reader->warnings();
    return true;
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
    return false;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Paths& p = paths();
  fibscope::fuzz::writeInput(p.input, data, size, size);
  fibscope::Tractogram all;
  fibscope::TractogramHeader header;
  std::vector<std::string> warnings;
  const bool ok = readAll(p.input, &all, &header, &warnings);
  writeGzip(p.gz, data, size);
  fibscope::Tractogram all_gz;
  std::vector<std::string> warnings_gz;
  const bool ok_gz = readAll(p.gz, &all_gz, nullptr, &warnings_gz);
  if (ok != ok_gz) std::abort();
  if (ok && (all_gz.offsets != all.offsets || all_gz.positions.size() != all.positions.size() ||
             (!all.positions.empty() && std::memcmp(all_gz.positions.data(), all.positions.data(),
                                                    all.positions.size() * sizeof(float)) != 0)))
    std::abort();
  // (The paths differ, so do the messages' first words: compare the rest.)
  if (ok && warnings_gz.size() != warnings.size()) std::abort();
  const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
  if (size % page != 0) {
    fibscope::fuzz::writeInput(p.padded, data, size, (size / page + 1) * page);
    readAll(p.padded, nullptr, nullptr);
  }
  if (ok) {
    try {
      fibscope::WriterOptions options;
      options.overwrite = true;
      std::vector<std::string> dropped;  // arrays trk cannot name (more than 10) are dropped with a warning
      fibscope::writeTractogram(p.output, all, header, options, &dropped);
      fibscope::Tractogram back;
      if (!readAll(p.output, &back, nullptr)) std::abort();  // what we write, we read
      if (back.offsets != all.offsets) std::abort();
      if (dropped.empty() && (back.per_point.size() != all.per_point.size() ||
                              back.per_streamline.size() != all.per_streamline.size()))
        std::abort();
    } catch (const fibscope::Error& e) {
      fibscope::fuzz::checkMessage(e);  // e.g. a point outside the float range of the grid
    }
  }
  for (const auto* f : {&p.input, &p.padded, &p.output, &p.gz}) std::remove(f->c_str());
  return 0;
}
