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

namespace {

struct Paths {
  std::string input, padded;
};

const Paths& paths() {
  static const Paths p = [] {
    // /dev/shm when there is one: rewriting files on ext4 caps the run rate.
    const char* tmp = std::getenv("TMPDIR");
    struct stat st {};
    const std::string dir =
        ::stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode) ? "/dev/shm" : tmp && *tmp ? tmp : "/tmp";
    const std::string prefix = dir + "/fuzz_vtk." + std::to_string(::getpid()) + ".";
    return Paths{prefix + "input.vtk", prefix + "padded.vtk"};
  }();
  return p;
}

void writeFile(const std::string& path, const uint8_t* data, size_t size, size_t padded_size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  for (size_t i = size; i < padded_size; ++i) std::fputc(0, f);
  std::fclose(f);
}

void readAll(const std::string& path) {
  try {
    auto reader = fibscope::openVtk(path);
    fibscope::Tractogram chunk;
    uint64_t streamlines = 0;
    while (reader->read(chunk, 16)) {
      if (!chunk.validate().empty() || chunk.streamlineCount() == 0) std::abort();
      if (chunk.per_point.size() != reader->header().per_point.size()) std::abort();
      streamlines += chunk.streamlineCount();
    }
    if (int64_t(streamlines) != reader->header().declared_streamlines) std::abort();
    if (reader->bytesRead() > reader->header().file_bytes) std::abort();
  } catch (const fibscope::Error& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) std::abort();  // messages are one line
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Paths& p = paths();
  writeFile(p.input, data, size, size);
  readAll(p.input);
  const size_t page = static_cast<size_t>(::sysconf(_SC_PAGESIZE));
  if (size % page != 0) {
    writeFile(p.padded, data, size, (size / page + 1) * page);
    readAll(p.padded);
  }
  std::remove(p.input.c_str());
  std::remove(p.padded.c_str());
  return 0;
}
