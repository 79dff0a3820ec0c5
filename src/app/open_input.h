// Opening any tractogram input of the command line: the formats of
// io/format.cpp plus .fbl (decoded fiblets), which lives in the codec
// library and so is dispatched here rather than in io/.
#pragma once

#include <memory>
#include <string>

#include "io/reader.h"

namespace fibscope {

// True when `path` ends in ".fbl" (any case).
bool isFblPath(const std::string& path);

// openFbl for *.fbl, else openTractogram. Throws Error as those do.
std::unique_ptr<TractogramReader> openInput(const std::string& path);

}  // namespace fibscope
