// What every reader's fuzz target shares: a per-process scratch file for the
// input (readers take paths), and the checks on what a reader hands out.
#pragma once

#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/error.h"
#include "io/reader.h"

namespace fibscope::fuzz {

// "<dir>/fuzz_<target>.<pid>.<name>": /dev/shm when there is one, since
// rewriting a file on ext4 flushes it on close and caps the run rate at
// ~100 runs/s; named by pid so parallel jobs do not collide. Callers remove
// their files after each input: libFuzzer may end with _Exit, skipping atexit.
inline std::string scratchPath(const std::string& target, const std::string& name) {
  const char* tmp = std::getenv("TMPDIR");
  struct stat st {};
  const std::string dir = ::stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode) ? "/dev/shm"
                          : tmp && *tmp                                       ? tmp
                                                                              : "/tmp";
  return dir + "/fuzz_" + target + "." + std::to_string(::getpid()) + "." + name;
}

// Writes `size` bytes, zero-padded to `padded_size` (>= size).
inline void writeInput(const std::string& path, const uint8_t* data, size_t size, size_t padded_size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  for (size_t i = size; i < padded_size; ++i) std::fputc(0, f);
  std::fclose(f);
}

inline void writeInput(const std::string& path, const uint8_t* data, size_t size) {
  writeInput(path, data, size, size);
}

// Bad input must give one-line messages.
inline void checkMessage(const Error& e) {
  if (std::string(e.what()).find('\n') != std::string::npos) std::abort();
}

// A chunk must keep the Tractogram invariants and the reader's progress
// must stay within the file.
inline void checkChunk(const TractogramReader& reader, const Tractogram& chunk) {
  if (!chunk.validate().empty()) std::abort();
  if (reader.bytesRead() > reader.header().file_bytes) std::abort();
}

// Reads all of what open() returns, `max_points` at a time, checking each
// chunk; an Error (thrown by open() or a read) is an accepted end.
template <typename Open>
void readAllChecked(Open open, size_t max_points) {
  try {
    auto reader = open();
    Tractogram chunk;
    while (reader->read(chunk, max_points)) checkChunk(*reader, chunk);
  } catch (const Error& e) {
    checkMessage(e);
  }
}

}  // namespace fibscope::fuzz
