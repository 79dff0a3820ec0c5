#include "render/gpu_tractogram_upload.h"

#include <chrono>

#include "codec/fiblet_encoder.h"

namespace fibscope {

std::vector<float> streamlineLengths(const Tractogram& tractogram) {
  std::vector<float> lengths(tractogram.streamlineCount());
  for (size_t s = 0; s < lengths.size(); ++s)
    lengths[s] = polylineLength(tractogram.point(tractogram.offsets[s]), tractogram.pointsIn(s));
  return lengths;
}

TractogramUpload uploadTractogram(const gpu::VulkanContext& context, const Tractogram& tractogram,
                                  const std::string& name, Progress* progress) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  TractogramUpload out;
  out.params = chooseCodecParams(tractogram);
  const EncodedFiblets encoded = encodeTractogram(tractogram, out.params);
  const std::vector<float> lengths = streamlineLengths(tractogram);
  const auto t1 = Clock::now();
  out.dataset = GpuDataset::upload(context, encoded, out.params, lengths, name, progress);
  out.encode_seconds = std::chrono::duration<double>(t1 - t0).count();
  out.upload_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  return out;
}

}  // namespace fibscope
