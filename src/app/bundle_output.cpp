#include "app/bundle_output.h"

#include <memory>

#include "codec/compressor.h"
#include "app/open_input.h"
#include "core/error.h"
#include "io/writer.h"

namespace fibscope {

namespace {

// The model handed to the compressor in one chunk (it reads its input
// twice: the factory makes a fresh reader each time).
class MemoryReader final : public TractogramReader {
 public:
  MemoryReader(const Tractogram& tractogram, const TractogramHeader& header) : tractogram_(tractogram) {
    header_ = header;
    header_.declared_streamlines = int64_t(tractogram.streamlineCount());
    header_.declared_points = int64_t(tractogram.pointCount());
  }
  bool read(Tractogram& chunk, size_t) override {
    if (done_) return false;
    chunk = tractogram_;
    done_ = true;
    return true;
  }
  uint64_t bytesRead() const override { return 0; }

 private:
  const Tractogram& tractogram_;
  bool done_ = false;
};

std::string extensionOf(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return path.substr(dot);
}

}  // namespace

void checkBundledOutputPath(const std::string& path) {
  if (isFblPath(path)) return;
  const std::string ext = extensionOf(path);
  if (ext != ".tck" && ext != ".trk" && ext != ".trx")
    fail(path, "unknown output format (use .tck, .trk, .trx or .fbl)");
}

std::vector<std::string> writeBundledTractogram(const std::string& path, const Tractogram& tractogram,
                                                const TractogramHeader& header, bool overwrite) {
  checkBundledOutputPath(path);
  if (isFblPath(path)) {
    CompressOptions co;
    co.overwrite = overwrite;
    co.resample = true;  // bundled fibers no longer have a constant step
    const CompressReport r =
        compressTractogram([&] { return std::make_unique<MemoryReader>(tractogram, header); }, path, co);
    return r.warnings;
  }
  WriterOptions wo;
  wo.overwrite = overwrite;
  std::vector<std::string> warnings;
  writeTractogram(path, tractogram, header, wo, &warnings);
  return warnings;
}

}  // namespace fibscope
