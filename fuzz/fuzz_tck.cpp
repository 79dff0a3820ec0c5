// libFuzzer target for the .tck reader and .tsf attachment.
//
// Each input is read twice: as a .tck, and as a .tsf attached to a fixed
// valid tractogram. Only fibscope::Error is an accepted outcome; a chunk
// that breaks the Tractogram invariants or a message with a line break
// aborts. Samples are parsed out of a heap buffer, so ASan sees any read
// past the data.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"

namespace {

// Files live only during one run (libFuzzer may end the process without
// running atexit handlers), named by pid so parallel jobs do not collide.
struct Paths {
  std::string tck, tsf, reference;
  std::string reference_bytes;  // streamlines of 2, 0 and 3 points, as the .tsf seeds expect
};

const Paths& paths() {
  static const Paths p = [] {
    // Memory-backed /dev/shm when there is one: rewriting a file in place on
    // ext4 flushes it on close, which would cap the fuzzer at ~100 runs/s.
    const char* tmp = std::getenv("TMPDIR");
    struct stat st {};
    const std::string dir = ::stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode) ? "/dev/shm"
                            : tmp && *tmp                                       ? tmp
                                                                                : "/tmp";
    const std::string prefix = dir + "/fuzz_tck." + std::to_string(::getpid()) + ".";
    Paths q;
    q.tck = prefix + "input.tck";
    q.tsf = prefix + "input.tsf";
    q.reference = prefix + "reference.tck";
    fibscope::Tractogram t;
    const float xyz[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    t.addStreamline(xyz, 2);
    t.addStreamline(xyz, 0);
    t.addStreamline(xyz, 3);
    fibscope::WriterOptions options;
    options.overwrite = true;
    fibscope::writeTractogram(q.reference, t, {}, options);
    FILE* f = std::fopen(q.reference.c_str(), "rb");
    if (!f) std::abort();
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) q.reference_bytes.append(buffer, n);
    std::fclose(f);
    std::remove(q.reference.c_str());
    return q;
  }();
  return p;
}

void writeFile(const std::string& path, const uint8_t* data, size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  std::fclose(f);
}

void readAll(const std::string& tck, const std::vector<std::string>& tsf) {
  try {
    auto reader = fibscope::openTck(tck, tsf);
    fibscope::Tractogram chunk;
    while (reader->read(chunk, 16)) {
      if (!chunk.validate().empty() || chunk.streamlineCount() == 0) std::abort();
      if (reader->bytesRead() > reader->header().file_bytes) std::abort();
    }
  } catch (const fibscope::Error& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) std::abort();  // messages are one line
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Paths& p = paths();
  writeFile(p.tck, data, size);
  readAll(p.tck, {});
  writeFile(p.tsf, data, size);
  writeFile(p.reference, reinterpret_cast<const uint8_t*>(p.reference_bytes.data()), p.reference_bytes.size());
  readAll(p.reference, {p.tsf});
  for (const auto* f : {&p.tck, &p.tsf, &p.reference}) std::remove(f->c_str());
  return 0;
}
