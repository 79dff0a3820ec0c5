// libFuzzer target for the legacy VTK PolyData reader.
//
// Each input is read twice: as given, and zero-padded to whole pages so that
// the data ends on a page boundary and a read past the end of the map
// faults (ASan does not watch mapped files). Only fibscope::Error is an
// accepted outcome; a chunk that breaks the Tractogram invariants aborts.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "io/reader.h"
#include "fuzz_support.h"

namespace {

struct Paths {
  std::string input, padded;
};

const Paths& paths() {
  static const Paths p = [] {
    auto prefix = [](const std::string& name) { return fibscope::fuzz::scratchPath("vtk", name); };
    return Paths{prefix("input.vtk"), prefix("padded.vtk")};
  }();
  return p;
}

void readAll(const std::string& path) {
  try {
    auto reader = fibscope::openVtk(path);
    fibscope::Tractogram chunk;
    uint64_t streamlines = 0;
    while (reader->read(chunk, 16)) {
      fibscope::fuzz::checkChunk(*reader, chunk);
      if (chunk.streamlineCount() == 0) std::abort();
      if (chunk.per_point.size() != reader->header().per_point.size()) std::abort();
      streamlines += chunk.streamlineCount();
    }
    if (int64_t(streamlines) != reader->header().declared_streamlines) std::abort();
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Paths& p = paths();
  fibscope::fuzz::writeInput(p.input, data, size, size);
  readAll(p.input);
  const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
  if (size % page != 0) {
    fibscope::fuzz::writeInput(p.padded, data, size, (size / page + 1) * page);
    readAll(p.padded);
  }
  std::remove(p.input.c_str());
  std::remove(p.padded.c_str());
  return 0;
}
