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
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = fibscope::fuzz::scratchPath("trx", "input.trx");
  fibscope::fuzz::writeInput(path, data, size);
  fibscope::fuzz::readAllChecked([&] { return fibscope::openTrx(path); }, 16);
  ::unlink(path.c_str());
  return 0;
}
