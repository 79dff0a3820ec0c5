// What an interrupted command leaves behind: nothing. Outputs are written
// under temporary names (OutputFile, the TRX writer's directory) that the
// normal paths and exceptions remove; a SIGINT, SIGTERM or SIGHUP would end
// the process before those destructors run and leave the partial output
// (hundreds of MB for a large input) beside the target. Temporary paths are
// therefore registered here while they exist, and installInterruptCleanup
// has one thread wait for those signals (blocked in every other thread), then
// remove every registered path, and anything whose name extends it (libzip
// writes "<archive>.XXXXXX" before its rename), and end the process by the
// same signal.
#pragma once

#include <string>

namespace fibscope {

// Call once from main() before any other thread starts (the signals are
// blocked in the calling thread and so in every thread it starts later).
void installInterruptCleanup();

// A file or directory (removed with its contents) to delete if the process
// is interrupted. Register before creating it; unregister once it is renamed
// into place or removed. Thread-safe; cheap (a mutex and a small list).
void registerTemporaryPath(const std::string& path);
void unregisterTemporaryPath(const std::string& path);

// The removal an interrupt performs, without the interrupt (tests). Returns
// how many registered paths were removed.
size_t removeTemporaryPathsForInterrupt();

}  // namespace fibscope
