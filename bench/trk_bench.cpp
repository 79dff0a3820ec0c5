// .trk read and write speed.
//
//   FIBSCOPE_BENCH_TRK=brain.trk bench/trk_bench
//
// Without FIBSCOPE_BENCH_TRK the benchmark uses $TMPDIR/fibscope_bench_256m.trk
// and first writes it with the trk writer if it is missing: ~256 MB of
// random-walk streamlines of about 800 points (0.5 mm steps) with one
// per-point scalar, on an oblique LPS grid so that the full voxmm -> RAS
// affine is exercised. The file is read once before timing so that the
// figure is parsing speed, not disk speed. Reported as bytes/s of file and
// points/s (items).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "io/reader.h"
#include "io/writer.h"

namespace fibscope {
namespace {

TractogramHeader benchHeader() {
  TractogramHeader h;
  h.format = "trk";
  h.space.known = true;
  const float c = std::cos(0.3f), s = std::sin(0.3f);
  h.space.voxel_to_rasmm = {1.25f * c, -1.25f * s, 0, -90, 1.25f * s, 1.25f * c, 0, -120, 0, 0, 1.5f, -70, 0, 0, 0, 1};
  h.space.dimensions = {145, 174, 145};
  h.space.voxel_sizes = {1.25f, 1.25f, 1.5f};
  h.space.voxel_order = "LPS";
  h.per_point = {{"fa", 1, "float32", {}}};
  return h;
}

// Streamlines of ~800 points until about `bytes` of trk data.
Tractogram randomWalks(size_t streamlines, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 1.f);
  Tractogram t;
  t.per_point = {{"fa", 1, "float32", {}}};
  for (size_t i = 0; i < streamlines; ++i) {
    const size_t n = 600 + rng() % 400;
    float p[3] = {40 * g(rng), 40 * g(rng), 40 * g(rng)}, d[3] = {g(rng), g(rng), g(rng)};
    for (size_t j = 0; j < n; ++j) {
      const float norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + 1e-6f;
      for (int k = 0; k < 3; ++k) {
        t.positions.push_back(p[k]);
        p[k] += 0.5f * d[k] / norm;
        d[k] = d[k] / norm + 0.15f * g(rng);
      }
      t.per_point[0].values.push_back(0.5f + 0.1f * g(rng));
    }
    t.offsets.push_back(t.offsets.back() + n);
  }
  return t;
}

std::string benchFile() {
  if (const char* env = std::getenv("FIBSCOPE_BENCH_TRK")) return env;
  const char* tmp = std::getenv("TMPDIR");
  const std::string path = std::string(tmp && *tmp ? tmp : "/tmp") + "/fibscope_bench_256m.trk";
  if (!std::filesystem::exists(path)) {
    // 16 bytes per point (x y z fa): 256 MB is ~16.8 M points, ~21 k streamlines.
    auto writer = createTrkWriter(path, benchHeader(), {});
    for (unsigned block = 0; block < 21; ++block) writer->write(randomWalks(1000, block));
    writer->finish();
  }
  return path;
}

void TrkRead(benchmark::State& state) {
  const std::string path = benchFile();
  Tractogram chunk;
  { auto warm = openTrk(path); while (warm->read(chunk)) {} }
  uint64_t bytes = 0, points = 0;
  for (auto _ : state) {
    auto reader = openTrk(path);
    while (reader->read(chunk)) points += chunk.pointCount();
    bytes += reader->bytesRead();
  }
  state.SetBytesProcessed(int64_t(bytes));
  state.SetItemsProcessed(int64_t(points));
}
BENCHMARK(TrkRead)->UseRealTime()->Unit(benchmark::kMillisecond);

void TrkWrite(benchmark::State& state) {
  const Tractogram t = randomWalks(2000, 99);  // ~25 MB of trk
  const char* tmp = std::getenv("TMPDIR");
  const std::string path = std::string(tmp && *tmp ? tmp : "/tmp") + "/fibscope_bench_write.trk";
  WriterOptions options;
  options.overwrite = true;
  uint64_t bytes = 0;
  for (auto _ : state) {
    writeTractogram(path, t, benchHeader(), options);
    bytes += std::filesystem::file_size(path);
  }
  std::filesystem::remove(path);
  state.SetBytesProcessed(int64_t(bytes));
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(t.pointCount()));
}
BENCHMARK(TrkWrite)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace fibscope

BENCHMARK_MAIN();
