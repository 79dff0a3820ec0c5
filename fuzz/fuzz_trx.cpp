// libFuzzer target for the TRX reader. The input bytes are a .trx file (a
// zip archive); everything is read in small chunks. Only fibscope::Error is
// an acceptable outcome of bad input: any other exception, a crash, a chunk
// that breaks the Tractogram invariants or a multi-line message aborts so
// the fuzzer reports it.
//
// Seeds: fuzz/seeds/trx_seeds.sh DIR writes small valid TRX zips.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "io/reader.h"

namespace {

// One input file path per process, reused for every input (the file is
// removed after each input: libFuzzer may end with _Exit, skipping atexit).
const std::string& inputPath() {
  static const std::string path = [] {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir && *dir ? dir : "/tmp") + "/fuzz_trx_" + std::to_string(::getpid()) + ".trx";
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = inputPath();
  FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, file) != size) std::abort();
  std::fclose(file);
  try {
    auto reader = fibscope::openTrx(path);
    fibscope::Tractogram chunk;
    while (reader->read(chunk, 16)) {
      if (!chunk.validate().empty()) std::abort();
    }
    if (reader->bytesRead() > reader->header().file_bytes) std::abort();
  } catch (const fibscope::Error& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) std::abort();
  }
  ::unlink(path.c_str());
  return 0;
}
