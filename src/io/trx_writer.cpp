// Placeholder until the trx writer lands (replaced by the real writer).
#include "core/error.h"
#include "io/writer.h"
namespace fibscope {
std::unique_ptr<TractogramWriter> createTrxWriter(const std::string& path, const TractogramHeader&, const WriterOptions&) {
  fail(path, "trx writer not built yet");
}
}  // namespace fibscope
