// libFuzzer target for what a TRX's header.json says (io/trx_reader.cpp).
//
// fuzz_trx mutates whole zip archives, whose CRCs stop nearly every change
// to the header's text before the reader parses it; here the input IS
// header.json, placed in a fixed, valid TRX directory (2 streamlines of 2
// and 3 points, a per-streamline, a per-point and a group array), so the
// fuzzer works on the JSON and the counts, affine and dimensions it
// declares against the members. Only fibscope::Error on one line is an
// accepted outcome; chunks keep the Tractogram invariants. (A number beyond
// double's range escaped as nlohmann's out_of_range once.)
// Seeds: fuzz/seeds/trxheader.sh.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "fuzz_support.h"
#include "io/reader.h"

namespace {

void put(const std::string& path, const void* data, size_t size) {
  fibscope::fuzz::writeInput(path, static_cast<const uint8_t*>(data), size);
}

const char* const kMembers[] = {"/positions.3.float32", "/offsets.uint64", "/dps/weight.float32",
                                "/dpv/fa.float32", "/groups/second.uint32", "/header.json"};
const char* const kFolders[] = {"/dps", "/dpv", "/groups", ""};

// The directory, made anew for each input and removed after it (in
// /dev/shm: cheap), so that no run leaves anything behind; only
// header.json differs between inputs.
void makeDirectory(const std::string& d) {
  for (const char* sub : {"", "/dps", "/dpv", "/groups"})
    if (::mkdir((d + sub).c_str(), 0700) != 0 && errno != EEXIST) std::abort();
  const float positions[15] = {0, 0, 0, 1, 0, 0, 5, 5, 5, 6, 5, 5, 7, 5, 5};
  const uint64_t offsets[3] = {0, 2, 5};
  const float weight[2] = {0.25f, 0.75f};
  const float fa[5] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f};
  const uint32_t group[1] = {1};
  put(d + kMembers[0], positions, sizeof positions);
  put(d + kMembers[1], offsets, sizeof offsets);
  put(d + kMembers[2], weight, sizeof weight);
  put(d + kMembers[3], fa, sizeof fa);
  put(d + kMembers[4], group, sizeof group);
}

void removeDirectory(const std::string& d) {
  for (const char* m : kMembers) ::unlink((d + m).c_str());
  for (const char* f : kFolders) ::rmdir((d + f).c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string dir = fibscope::fuzz::scratchPath("trxheader", "ref.trx");
  makeDirectory(dir);
  fibscope::fuzz::writeInput(dir + "/header.json", data, size);
  fibscope::fuzz::readAllChecked([&] { return fibscope::openTrx(dir); }, 1);
  removeDirectory(dir);
  return 0;
}
