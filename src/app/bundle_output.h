// The bundled model written as `fibscope bundle` writes it, by the output's
// extension: .tck .trk .trx through io/writer.h, .fbl through the compressor
// (resampled: bundled fibers no longer have a constant step). Shared by the
// command (cmd_bundle.cpp) and the viewer's "Save bundled..." (viewer_bundling).
#pragma once

#include <string>
#include <vector>

#include "core/tractogram.h"
#include "io/reader.h"

namespace fibscope {

// Throws Error naming `path` for an unknown extension, an existing file
// without `overwrite`, or a failed write. Returns the writer's warnings.
std::vector<std::string> writeBundledTractogram(const std::string& path, const Tractogram& tractogram,
                                                const TractogramHeader& header, bool overwrite);

// Throws Error naming `path` unless its extension is one writeBundledTractogram takes.
void checkBundledOutputPath(const std::string& path);

}  // namespace fibscope
