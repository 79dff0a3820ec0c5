// Placeholder until the tck writer lands (replaced by the real writer).
#include "core/error.h"
#include "io/writer.h"
namespace fibscope {
std::unique_ptr<TractogramWriter> createTckWriter(const std::string& path, const TractogramHeader&, const WriterOptions&) {
  fail(path, "tck writer not built yet");
}
}  // namespace fibscope
