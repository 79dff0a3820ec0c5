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
#include "fuzz_support.h"

namespace {

// Files live only during one run (libFuzzer may end the process without
// running atexit handlers), named by pid so parallel jobs do not collide.
struct Paths {
  std::string tck, tsf, reference;
  std::string reference_bytes;  // streamlines of 2, 0 and 3 points, as the .tsf seeds expect
};

const Paths& paths() {
  static const Paths p = [] {
    Paths q;
    q.tck = fibscope::fuzz::scratchPath("tck", "input.tck");
    q.tsf = fibscope::fuzz::scratchPath("tck", "input.tsf");
    q.reference = fibscope::fuzz::scratchPath("tck", "reference.tck");
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

void readAll(const std::string& tck, const std::vector<std::string>& tsf) {
  try {
    auto reader = fibscope::openTck(tck, tsf);
    fibscope::Tractogram chunk;
    while (reader->read(chunk, 16)) {
      fibscope::fuzz::checkChunk(*reader, chunk);
      if (chunk.streamlineCount() == 0) std::abort();
    }
  } catch (const fibscope::Error& e) {
    fibscope::fuzz::checkMessage(e);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const Paths& p = paths();
  fibscope::fuzz::writeInput(p.tck, data, size);
  readAll(p.tck, {});
  fibscope::fuzz::writeInput(p.tsf, data, size);
  fibscope::fuzz::writeInput(p.reference, reinterpret_cast<const uint8_t*>(p.reference_bytes.data()), p.reference_bytes.size());
  readAll(p.reference, {p.tsf});
  for (const auto* f : {&p.tck, &p.tsf, &p.reference}) std::remove(f->c_str());
  return 0;
}
