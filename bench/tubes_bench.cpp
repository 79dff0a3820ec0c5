// The tube model at the largest size (issue 15 item 1): 10^5
// fibers of 100 points, 10^7 nodes, built with every point kept and
// resampled at 0.01 mm; counters give the nodes made and the tubes
// buffer's bytes (48 per node + 16 per segment). Run an optimised build:
//   build/bench/tubes_bench --benchmark_filter=. --benchmark_repetitions=1
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/tractogram.h"
#include "tubes/tube_model.h"

namespace {

// Tracker-like random walks: 0.1 mm steps, turning at most ~6 degrees.
const fibscope::Tractogram& bigTractogram() {
  static const fibscope::Tractogram t = [] {
    fibscope::Tractogram out;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<float> xyz;
    for (int f = 0; f < 100000; ++f) {
      xyz.clear();
      float p[3] = {40 * u(rng), 40 * u(rng), 40 * u(rng)}, d[3] = {u(rng), u(rng), u(rng)};
      for (int i = 0; i < 100; ++i) {
        xyz.insert(xyz.end(), {p[0], p[1], p[2]});
        float l = 0;
        for (int k = 0; k < 3; ++k) {
          d[k] += 0.1f * u(rng);
          l += d[k] * d[k];
        }
        l = std::sqrt(l);
        for (int k = 0; k < 3; ++k) {
          d[k] /= l;
          p[k] += 0.1f * d[k];
        }
      }
      out.addStreamline(xyz.data(), 100);
    }
    return out;
  }();
  return t;
}

void BM_BuildTubes(benchmark::State& state) {
  const fibscope::Tractogram& t = bigTractogram();
  fibscope::TubeBuildOptions o;
  o.resample_tolerance = float(state.range(0)) * 1e-3f;
  size_t nodes = 0, bytes = 0;
  for (auto _ : state) {
    const fibscope::TubeModel m = fibscope::buildTubes(t, o);
    nodes = m.nodes.size();
    bytes = m.deviceBytes();
    benchmark::DoNotOptimize(m.nodes.data());
  }
  state.counters["points"] = double(t.pointCount());
  state.counters["nodes"] = double(nodes);
  state.counters["buffer_MB"] = double(bytes) / 1e6;
  state.counters["points_per_s"] =
      benchmark::Counter(double(t.pointCount()), benchmark::Counter::kIsIterationInvariantRate);
}
// Tolerance in micrometres: 0 keeps every point.
BENCHMARK(BM_BuildTubes)->Arg(0)->Arg(10)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
