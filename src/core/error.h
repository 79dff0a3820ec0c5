// Errors for bad input and failed system calls.
//
// Readers, writers and decoders throw fibscope::Error for anything a user can
// cause (a truncated file, a header that lies, an unwritable path). The
// message is one line that names the file first, then where (byte offset,
// section or archive member) and what was expected and found, e.g.
//   "brain.tck: byte 1048 : streamline 12 contains NaN inside its points".
// assert() is kept for programmer contracts only.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace fibscope {

// The message as one line: newlines and carriage returns become spaces (a
// library's message of several lines), every other control byte '?', and
// trailing spaces go. Names and text taken from input files (a trk scalar
// name, a TRX member, a JSON key) can hold any byte, and a message must stay
// one line whatever the file holds. UTF-8 (bytes >= 0x80) passes unchanged.
std::string oneLine(std::string message);

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(oneLine(message)) {}
};

// "PATH: MESSAGE"
[[noreturn]] void fail(const std::string& path, const std::string& message);
// "PATH: byte OFFSET: MESSAGE"
[[noreturn]] void failAt(const std::string& path, uint64_t offset, const std::string& message);
// "PATH: MESSAGE: strerror(errno)" for failed system calls.
[[noreturn]] void failErrno(const std::string& path, const std::string& message);

}  // namespace fibscope
