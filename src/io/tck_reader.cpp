// Placeholder until the tck reader lands (replaced by the real reader).
#include "core/error.h"
#include "io/reader.h"
namespace fibscope {
std::unique_ptr<TractogramReader> openTck(const std::string& path) { fail(path, "tck reader not built yet"); }
}  // namespace fibscope
