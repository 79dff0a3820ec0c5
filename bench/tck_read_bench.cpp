// .tck read speed: a whole file from the page cache into Tractogram chunks.
//
//   FIBSCOPE_BENCH_TCK=brain.tck bench/tck_read_bench
//
// Without FIBSCOPE_BENCH_TCK the benchmark uses $TMPDIR/fibscope_bench_1g.tck
// and first writes it with the tck writer if it is missing: ~1 GB of
// Float32LE random-walk streamlines of about 800 points (0.5 mm steps, as
// tckgen makes them). The file is read once before timing so that the
// figure is parsing speed, not disk speed. Reported as bytes/s of file.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/reader.h"
#include "io/writer.h"

namespace {

constexpr uint64_t kGeneratedBytes = uint64_t(1) << 30;

void generate(const std::string& path) {
  std::fprintf(stderr, "tck_read_bench: writing %s (~1 GB of random-walk streamlines)\n", path.c_str());
  fibscope::TractogramHeader like;
  like.properties = {{"command_history", "tck_read_bench (random walks, 0.5 mm steps)"}};
  auto writer = fibscope::createTckWriter(path, like, {});
  std::mt19937 rng(2024);
  std::normal_distribution<float> turn(0.f, 0.15f);
  std::uniform_int_distribution<int> length(600, 1000);  // mean 800 points
  std::uniform_real_distribution<float> start(-60.f, 60.f);
  fibscope::Tractogram chunk;
  std::vector<float> xyz;
  uint64_t bytes = 0;
  while (bytes < kGeneratedBytes) {
    const int n = length(rng);
    float p[3] = {start(rng), start(rng), start(rng)};
    float d[3] = {1, 0, 0};
    xyz.clear();
    for (int i = 0; i < n; ++i) {
      const float norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (int k = 0; k < 3; ++k) {
        d[k] /= norm;
        xyz.push_back(p[k]);
        p[k] += 0.5f * d[k];
        d[k] += turn(rng);
      }
    }
    chunk.addStreamline(xyz.data(), static_cast<size_t>(n));
    bytes += 12 * (static_cast<uint64_t>(n) + 1);
    if (chunk.pointCount() >= (size_t(1) << 20)) {
      writer->write(chunk);
      chunk.clear();
    }
  }
  writer->write(chunk);
  writer->finish();
}

// Pulls the whole file into the page cache.
void warmPageCache(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw fibscope::Error(path + ": cannot open");
  std::vector<char> buffer(size_t(8) << 20);
  while (std::fread(buffer.data(), 1, buffer.size(), f) == buffer.size()) {
  }
  std::fclose(f);
}

void readTck(benchmark::State& state, const std::string& path) {
  uint64_t bytes = 0;
  uint64_t points = 0;
  for (auto _ : state) {
    auto reader = fibscope::openTck(path);
    fibscope::Tractogram chunk;
    while (reader->read(chunk)) {
      points += chunk.pointCount();
      benchmark::DoNotOptimize(chunk.positions.data());
    }
    bytes += reader->header().file_bytes;
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(bytes));
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  std::string path;
  try {
    const char* env = std::getenv("FIBSCOPE_BENCH_TCK");
    if (env && *env) {
      path = env;
    } else {
      const char* tmp = std::getenv("TMPDIR");
      path = std::string(tmp && *tmp ? tmp : "/tmp") + "/fibscope_bench_1g.tck";
      if (!std::filesystem::exists(path)) generate(path);
    }
    warmPageCache(path);
  } catch (const fibscope::Error& e) {
    std::fprintf(stderr, "tck_read_bench: %s\n", e.what());
    return 1;
  }
  std::fprintf(stderr, "tck_read_bench: %s, %.3f GB\n", path.c_str(), double(std::filesystem::file_size(path)) / 1e9);
  benchmark::RegisterBenchmark("TckRead/page_cache", readTck, path)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
