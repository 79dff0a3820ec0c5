// libFuzzer target for the VTK XML PolyData reader (io/vtp_reader.cpp):
// the XML, base64, block headers and the three decompressors. Only
// fibscope::Error on one line is an accepted outcome; chunks keep the
// Tractogram invariants. Seeds: fuzz/seeds/vtp.py (files VTK wrote).
#include <unistd.h>

#include <cstdint>
#include <string>

#include "core/error.h"
#include "fuzz_support.h"
#include "io/reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = fibscope::fuzz::scratchPath("vtp", "input.vtp");
  fibscope::fuzz::writeInput(path, data, size);
  fibscope::fuzz::readAllChecked([&] { return fibscope::openVtp(path); }, 16);
  ::unlink(path.c_str());
  return 0;
}
