#include "render/gpu/tractogram_upload.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <limits>

#include "codec/fiblet_encoder.h"
#include "core/error.h"
#include "core/thread_pool.h"

namespace fibscope {
namespace {

// Chunks of about this many points go to the workers, each copied into the
// worker's reused chunk (encode() runs two fibers at once, 1.5x the speed
// of one fiber at a time) and encoded into its own EncodedFiblets; the
// parts are uploaded in order, never joined in memory.
constexpr size_t kEncodeChunkPoints = size_t(1) << 18;

// The parts as GpuDataset::upload takes them (in input order).
std::vector<const EncodedFiblets*> partList(const std::deque<EncodedFiblets>& parts) {
  std::vector<const EncodedFiblets*> list;
  for (const EncodedFiblets& part : parts) list.push_back(&part);
  return list;
}

// Encoded parts in input order (uploaded without joining them).
std::deque<EncodedFiblets> encodeInParallel(const Tractogram& tractogram, const CodecParams& params) {
  // Fiber ranges of about kEncodeChunkPoints points, in order.
  std::vector<std::pair<size_t, size_t>> ranges;
  for (size_t s = 0; s < tractogram.streamlineCount();) {
    const size_t first = s;
    size_t points = 0;
    while (s < tractogram.streamlineCount() && (points == 0 || points + tractogram.pointsIn(s) <= kEncodeChunkPoints))
      points += tractogram.pointsIn(s++);
    ranges.emplace_back(first, s);
  }
  // Declared before the pool: the pool, destroyed first, finishes its jobs.
  std::deque<EncodedFiblets> parts(ranges.size());
  std::vector<std::unique_ptr<FibletEncoder>> encoders;
  ThreadPool pool;
  std::vector<Tractogram> chunks(pool.size());
  for (unsigned i = 0; i < pool.size(); ++i) encoders.push_back(std::make_unique<FibletEncoder>(params));
  std::vector<std::future<void>> done;
  for (size_t i = 0; i < ranges.size(); ++i) {
    done.push_back(pool.submit([&tractogram, range = ranges[i], part = &parts[i], &encoders, &chunks](unsigned worker) {
      Tractogram& chunk = chunks[worker];
      chunk.clear();
      for (size_t s = range.first; s < range.second; ++s)
        chunk.addStreamline(tractogram.point(tractogram.offsets[s]), tractogram.pointsIn(s));
      encoders[worker]->encode(chunk, *part);
    }));
  }
  for (auto& d : done) d.get();
  return parts;
}


}  // namespace

std::vector<float> streamlineLengths(const Tractogram& tractogram) {
  std::vector<float> lengths(tractogram.streamlineCount());
  for (size_t s = 0; s < lengths.size(); ++s)
    lengths[s] = polylineLength(tractogram.point(tractogram.offsets[s]), tractogram.pointsIn(s));
  return lengths;
}

StreamedUpload uploadStreamed(const gpu::VulkanContext& context,
                              const std::function<std::unique_ptr<TractogramReader>()>& open,
                              const std::string& name, Progress* progress) {
  return uploadStreamed([&]() -> const gpu::VulkanContext& { return context; }, open, name, progress);
}

StreamedUpload uploadStreamed(const ContextSource& context,
                              const std::function<std::unique_ptr<TractogramReader>()>& open,
                              const std::string& name, Progress* progress) {
  using Clock = std::chrono::steady_clock;
  StreamedUpload out;
  auto t0 = Clock::now();
  // Pass 1: codec parameters, the box, a sample of the points (PointSample).
  CodecParamEstimator estimator;
  Bounds& box = out.bounds;
  box.min.fill(std::numeric_limits<double>::infinity());
  box.max.fill(-std::numeric_limits<double>::infinity());
  PointSample sample;  // as samplePoints would of the whole file
  {
    auto reader = open();
    Tractogram chunk;
    while (reader->read(chunk, kEncodeChunkPoints)) {
      estimator.add(chunk);
      const Bounds b = tractogramBounds(chunk);
      for (int k = 0; k < 3; ++k) {
        box.min[k] = std::min(box.min[k], b.min[k]);
        box.max[k] = std::max(box.max[k], b.max[k]);
      }
      sample.add(chunk);
      out.points += chunk.pointCount();
      out.streamlines += chunk.streamlineCount();
      for (size_t s = 0; s < chunk.streamlineCount(); ++s) out.segments += chunk.pointsIn(s) > 1 ? chunk.pointsIn(s) - 1 : 0;
    }
    out.warnings = reader->warnings();
  }
  out.sample = sample.points();
  if (out.streamlines == 0) throw Error(name + ": no streamlines to render");
  try {
    out.upload.params = estimator.finish();  // throws for no points or an absurd box
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());
  }
  out.read_seconds = std::chrono::duration<double>(Clock::now() - t0).count();

  // Pass 2: chunks encoded on the pool as they are read, at most
  // 2 x workers in flight; parts and lengths kept in input order.
  t0 = Clock::now();
  // Declared before the pool, so that on an exception the pool (destroyed
  // first) finishes its jobs before what they write to goes away; deques,
  // so that appending never moves an element a job is writing.
  std::deque<EncodedFiblets> parts;
  std::deque<std::vector<float>> lengths;
  std::vector<std::unique_ptr<FibletEncoder>> encoders;
  ThreadPool pool;
  for (unsigned i = 0; i < pool.size(); ++i) encoders.push_back(std::make_unique<FibletEncoder>(out.upload.params));
  // Jobs with their chunks: a finished job's chunk is read into again
  // (its buffers keep their capacity, so reading does not fault in fresh
  // pages for every chunk).
  std::deque<std::pair<std::future<void>, std::shared_ptr<Tractogram>>> in_flight;
  std::vector<std::shared_ptr<Tractogram>> spare;
  auto retireOldest = [&] {
    in_flight.front().first.get();
    // Reused only once the job has let go of it (the pool may still hold
    // the finished task for a moment).
    if (in_flight.front().second.use_count() == 1) spare.push_back(std::move(in_flight.front().second));
    in_flight.pop_front();
  };
  {
    auto reader = open();
    for (;;) {
      if (in_flight.size() >= 2 * size_t(pool.size())) retireOldest();
      std::shared_ptr<Tractogram> chunk;
      if (spare.empty()) {
        chunk = std::make_shared<Tractogram>();
      } else {
        chunk = std::move(spare.back());
        spare.pop_back();
      }
      if (!reader->read(*chunk, kEncodeChunkPoints)) break;
      EncodedFiblets* part = &parts.emplace_back();
      std::vector<float>* part_lengths = &lengths.emplace_back();
      in_flight.emplace_back(pool.submit([chunk, part, part_lengths, &encoders](unsigned worker) {
        encoders[worker]->encode(*chunk, *part);
        part_lengths->resize(chunk->streamlineCount());
        for (size_t s = 0; s < part_lengths->size(); ++s)
          (*part_lengths)[s] = polylineLength(chunk->point(chunk->offsets[s]), chunk->pointsIn(s));
      }), chunk);
    }
  }
  for (auto& job : in_flight) job.first.get();
  std::vector<float> all_lengths;
  all_lengths.reserve(out.streamlines);
  for (const auto& l : lengths) all_lengths.insert(all_lengths.end(), l.begin(), l.end());
  out.upload.encode_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  const gpu::VulkanContext& device = context();
  const auto t1 = Clock::now();  // not counting a wait for the device
  out.upload.dataset = GpuDataset::upload(device, partList(parts), out.upload.params, all_lengths, name, progress);
  out.upload.upload_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  return out;
}

TractogramUpload uploadTractogram(const gpu::VulkanContext& context, const Tractogram& tractogram,
                                  const std::string& name, Progress* progress) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  TractogramUpload out;
  out.params = chooseCodecParams(tractogram);
  const std::deque<EncodedFiblets> parts = encodeInParallel(tractogram, out.params);
  const std::vector<float> lengths = streamlineLengths(tractogram);
  const auto t1 = Clock::now();
  out.dataset = GpuDataset::upload(context, partList(parts), out.params, lengths, name, progress);
  out.encode_seconds = std::chrono::duration<double>(t1 - t0).count();
  out.upload_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  return out;
}

}  // namespace fibscope
