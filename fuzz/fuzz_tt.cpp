// libFuzzer target for DSI Studio's TinyTrack reader (io/tt_reader.cpp).
//
// The input is the MAT-4 file as it is inside the .tt.gz (zlib reads a
// plain file through the same path, so the fuzzer works on the matrices
// and records, not on deflate): written as a .tt and read whole in small
// chunks. Only fibscope::Error on one line is an accepted outcome; chunks
// keep the Tractogram invariants and progress stays within the file.
// Seeds: fuzz/seeds/tt.py.
#include <unistd.h>

#include <cstdint>
#include <string>

#include "core/error.h"
#include "fuzz_support.h"
#include "io/reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = fibscope::fuzz::scratchPath("tt", "input.tt");
  fibscope::fuzz::writeInput(path, data, size);
  fibscope::fuzz::readAllChecked([&] { return fibscope::openTinyTrack(path); }, 64);
  ::unlink(path.c_str());
  return 0;
}
