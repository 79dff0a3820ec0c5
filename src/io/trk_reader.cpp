// Placeholder until the trk reader lands (replaced by the real reader).
#include "core/error.h"
#include "io/reader.h"
namespace fibscope {
std::unique_ptr<TractogramReader> openTrk(const std::string& path) { fail(path, "trk reader not built yet"); }
}  // namespace fibscope
