#include "render/gpu_tractogram_upload.h"

#include <chrono>
#include <future>

#include "codec/fiblet_encoder.h"
#include "core/thread_pool.h"

namespace fibscope {
namespace {

// Chunks of about this many points go to the workers, each copied into the
// worker's reused chunk (encode() runs two fibers at once, 1.5x the speed
// of one fiber at a time) and encoded into its own EncodedFiblets; the
// parts are then joined in order.
constexpr size_t kEncodeChunkPoints = size_t(1) << 18;

EncodedFiblets encodeInParallel(const Tractogram& tractogram, const CodecParams& params) {
  struct Part {
    size_t first = 0, end = 0;  // fibers
    EncodedFiblets encoded;
  };
  std::vector<Part> parts;
  for (size_t s = 0; s < tractogram.streamlineCount();) {
    Part part;
    part.first = s;
    size_t points = 0;
    while (s < tractogram.streamlineCount() && (points == 0 || points + tractogram.pointsIn(s) <= kEncodeChunkPoints))
      points += tractogram.pointsIn(s++);
    part.end = s;
    parts.push_back(std::move(part));
  }
  ThreadPool pool;
  std::vector<std::unique_ptr<FibletEncoder>> encoders;
  std::vector<Tractogram> chunks(pool.size());
  for (unsigned i = 0; i < pool.size(); ++i) encoders.push_back(std::make_unique<FibletEncoder>(params));
  std::vector<std::future<void>> done;
  for (Part& part : parts) {
    done.push_back(pool.submit([&tractogram, &part, &encoders, &chunks](unsigned worker) {
      Tractogram& chunk = chunks[worker];
      chunk.clear();
      for (size_t s = part.first; s < part.end; ++s)
        chunk.addStreamline(tractogram.point(tractogram.offsets[s]), tractogram.pointsIn(s));
      encoders[worker]->encode(chunk, part.encoded);
    }));
  }
  for (auto& d : done) d.get();
  EncodedFiblets all;
  all.record_bytes = parts.empty() ? uint32_t(params.recordBytes()) : parts.front().encoded.record_bytes;
  size_t bytes = 0, fibers = 0;
  for (const Part& part : parts) {
    bytes += part.encoded.bytes.size();
    fibers += part.encoded.fiberCount();
  }
  all.bytes.reserve(bytes);
  all.fiber_first_fiblet.reserve(fibers);
  all.fiber_points.reserve(fibers);
  for (const Part& part : parts) {
    const uint32_t base = uint32_t(all.fibletCount());
    all.bytes.insert(all.bytes.end(), part.encoded.bytes.begin(), part.encoded.bytes.end());
    for (uint32_t first : part.encoded.fiber_first_fiblet) all.fiber_first_fiblet.push_back(base + first);
    all.fiber_points.insert(all.fiber_points.end(), part.encoded.fiber_points.begin(), part.encoded.fiber_points.end());
  }
  return all;
}

}  // namespace

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
  const EncodedFiblets encoded = encodeInParallel(tractogram, out.params);
  const std::vector<float> lengths = streamlineLengths(tractogram);
  const auto t1 = Clock::now();
  out.dataset = GpuDataset::upload(context, encoded, out.params, lengths, name, progress);
  out.encode_seconds = std::chrono::duration<double>(t1 - t0).count();
  out.upload_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  return out;
}

}  // namespace fibscope
