// Helpers shared by the tests: temporary directories, running the fibscope
// executable and helper scripts, small synthetic tractograms.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/tractogram.h"
#include "io/reader.h"

namespace fibscope::test {

// A fresh directory under $TMPDIR, removed with its contents on destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line and captures its output.
CommandResult runCommand(const std::string& command_line);
// Runs the built fibscope executable with `args` (already shell-quoted).
CommandResult runFibscope(const std::string& args);
// Path of the Python interpreter that has Debian's nibabel, "" if none.
std::string pythonWithNibabel();
// Path of a script in tests/tools.
std::string toolPath(const std::string& name);

void writeBytes(const std::string& path, const std::string& bytes);
std::string readBytes(const std::string& path);
// `bytes` as a gzip file's bytes (zlib's deflate with the gzip wrapper, as
// gzip(1) and Python's gzip module write them).
std::string gzipBytes(const std::string& bytes, int level = 6);

// A small deterministic tractogram: `streamlines` curved fibers of 2..60
// points in a 100 mm box, with optional data arrays.
Tractogram smallTractogram(size_t streamlines, unsigned seed = 1, bool with_data = false);

// The built-in phantom's first `streamlines` fibers (one thread, `seed`)
// written as dir/name in .tck, without per-streamline data; returns the path.
std::string writePhantomTck(const TempDir& dir, const std::string& name, uint64_t streamlines, uint64_t seed);

// The message of the Error `f` throws; empty when it throws none.
std::string errorOf(const std::function<void()>& f);

// Opens a reader with `open` and reads it all, `max_points` at a time,
// checking each chunk's invariants (EXPECT); "" or the Error's message.
// The tractogram, warnings and header go where given.
std::string readChunked(const std::function<std::unique_ptr<TractogramReader>()>& open, Tractogram* out = nullptr,
                        std::vector<std::string>* warnings = nullptr, TractogramHeader* header = nullptr,
                        size_t max_points = size_t(1) << 20);

// An 8-bit RGBA image read from a PNG.
struct Png {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
  const uint8_t* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * width + x) * 4]; }
};
// Decodes the PNGs writePngRgba writes (8-bit RGBA, filter 0 on every row);
// anything else gives an empty image (a test failure where one is read).
Png readOurPng(const std::string& path);
// Pixels whose RGB differs between a and b (all of them when the sizes differ).
size_t differingPixels(const Png& a, const Png& b);
// Pixels brighter than a black background (R + G + B > 30).
size_t drawnPixels(const Png& p);

}  // namespace fibscope::test
