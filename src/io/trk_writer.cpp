// Placeholder until the trk writer lands (replaced by the real writer).
#include "core/error.h"
#include "io/writer.h"
namespace fibscope {
std::unique_ptr<TractogramWriter> createTrkWriter(const std::string& path, const TractogramHeader&, const WriterOptions&) {
  fail(path, "trk writer not built yet");
}
}  // namespace fibscope
