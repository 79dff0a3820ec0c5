// Placeholder until the trx reader lands (replaced by the real reader).
#include "core/error.h"
#include "io/reader.h"
namespace fibscope {
std::unique_ptr<TractogramReader> openTrx(const std::string& path) { fail(path, "trx reader not built yet"); }
}  // namespace fibscope
