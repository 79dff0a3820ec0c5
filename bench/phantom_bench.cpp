// Phantom generation speed, in points per second (items = points).
//
//   PhantomRead/threads:N    steady-state streaming: one reader of an endless
//                            phantom, one 1 M-point chunk per iteration
//                            (what `fibscope phantom` feeds its writer)
//   PhantomGenerate          the per-streamline kernel on the calling thread,
//                            without the reader's threads and copies
//   Phantom10M/threads:N     generates a 20 k-fiber sample of the 10 M-fiber
//                            phantom at 0.1 mm and projects its size (points,
//                            segments, tck bytes) and generation time
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdint>

#include "phantom/phantom.h"

namespace fibscope {
namespace {

constexpr size_t kChunkPoints = size_t(1) << 20;

void PhantomRead(benchmark::State& state) {
  PhantomOptions options;
  options.streamlines = uint64_t(1) << 40;  // never runs out
  options.threads = unsigned(state.range(0));
  auto reader = openPhantom(options);
  Tractogram chunk;
  reader->read(chunk, kChunkPoints);  // warm-up: buffers allocated, prefetch running
  uint64_t points = 0;
  for (auto _ : state) {
    reader->read(chunk, kChunkPoints);
    points += chunk.pointCount();
    benchmark::DoNotOptimize(chunk.positions.data());
  }
  state.SetItemsProcessed(int64_t(points));
}
BENCHMARK(PhantomRead)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

void PhantomGenerate(benchmark::State& state) {
  PhantomOptions options;
  const PhantomGenerator generator(options);
  PhantomScratch scratch;
  std::vector<float> xyz;
  uint64_t index = 0, points = 0;
  for (auto _ : state) {
    xyz.clear();
    generator.generate(index++, xyz, scratch);
    points += xyz.size() / 3;
    benchmark::DoNotOptimize(xyz.data());
  }
  state.SetItemsProcessed(int64_t(points));
}
BENCHMARK(PhantomGenerate)->Unit(benchmark::kMicrosecond);

void Phantom10M(benchmark::State& state) {
  constexpr uint64_t kFibers = 10'000'000, kSample = 20'000;
  PhantomOptions options;
  options.streamlines = kSample;
  options.threads = unsigned(state.range(0));
  uint64_t points = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    auto reader = openPhantom(options);
    Tractogram chunk;
    uint64_t sample_points = 0;
    while (reader->read(chunk, kChunkPoints)) sample_points += chunk.pointCount();
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    points += sample_points;
  }
  state.SetItemsProcessed(int64_t(points));
  const double points_per_fiber = double(points) / double(state.iterations() * kSample);
  const double projected_points = points_per_fiber * double(kFibers);
  const double projected_segments = projected_points - double(kFibers);
  const double points_per_second = double(points) / seconds;
  state.counters["fibers_M"] = double(kFibers) / 1e6;
  state.counters["mean_length_mm"] = (points_per_fiber - 1.0) * options.step_mm;
  state.counters["segments_G"] = projected_segments / 1e9;
  // tck: 3 float32 per point plus one NaN triple ending each streamline.
  state.counters["tck_GB"] = (12.0 * projected_points + 12.0 * double(kFibers)) / 1e9;
  state.counters["projected_s"] = projected_points / points_per_second;
}
BENCHMARK(Phantom10M)->ArgName("threads")->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace fibscope

BENCHMARK_MAIN();
