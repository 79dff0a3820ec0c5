// Fiblet codec speed on the CPU, in points per second (items = points), on
// a 2000-fiber phantom at 0.1 mm (single thread).
//
//   CodecEncode/closed   closed-loop encode (5x5 candidate search per point)
//   CodecEncode/open     open-loop encode (the paper's)
//   CodecDecodeSequential / CodecDecodeScan   one fiblet after the other into
//                        normalised points; Scan is the CPU emulation of the
//                        GPU's log-step prefix (log2(59) = 6 compose rounds
//                        over all lanes, so more work than sequential)
//   CodecMeasureError    decode + world-space comparison (codec_error)
//   CodecEncodeThreads/T/M closed-loop encode of chunks of 200 fibers on T
//                        threads (the compressor's pool), wall-clock rate;
//                        M = 1 measures every point's error as compress does
//   FblDecompressToPoints/order  an .fbl of the phantom read back through
//                        openFbl into world-space float points (checksums,
//                        table checks, decode, toWorld): what `decompress`
//                        does before writing; order 0 sequential, 1 scan
#include <benchmark/benchmark.h>

#include <array>

#include "codec/codec_error.h"
#include "codec/codec_params.h"
#include "codec/compressor.h"
#include "codec/fbl_reader.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "core/thread_pool.h"
#include "io/reader.h"
#include "phantom/phantom.h"

namespace fibscope {
namespace {

const Tractogram& benchPhantom() {
  static const Tractogram tractogram = [] {
    PhantomOptions options;
    options.streamlines = 2000;
    options.seed = 3;
    return readAllStreamlines(*openPhantom(options));
  }();
  return tractogram;
}

void CodecEncode(benchmark::State& state) {
  const Tractogram& t = benchPhantom();
  const CodecParams params = chooseCodecParams(t);
  EncodeOptions options;
  options.mode = state.range(0) ? EncodeMode::ClosedLoop : EncodeMode::OpenLoop;
  for (auto _ : state) {
    EncodedFiblets f = encodeTractogram(t, params, options);
    benchmark::DoNotOptimize(f.bytes.data());
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(t.pointCount()));
  state.SetLabel(options.mode == EncodeMode::ClosedLoop ? "closed" : "open");
}
BENCHMARK(CodecEncode)->ArgName("closed")->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

template <bool kScan>
void CodecDecode(benchmark::State& state) {
  const Tractogram& t = benchPhantom();
  const CodecParams params = chooseCodecParams(t);
  const EncodedFiblets f = encodeTractogram(t, params);
  const FibletDecoder decoder(params);
  std::array<float, 3 * shader::kFibletMaxPoints> xyz;
  for (auto _ : state) {
    for (size_t i = 0; i < f.fibletCount(); ++i) {
      if constexpr (kScan)
        decoder.decodeScan(f.record(i), xyz.data());
      else
        decoder.decodeSequential(f.record(i), xyz.data());
      benchmark::DoNotOptimize(xyz.data());
    }
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(t.pointCount()));
}
void CodecDecodeSequential(benchmark::State& state) { CodecDecode<false>(state); }
void CodecDecodeScan(benchmark::State& state) { CodecDecode<true>(state); }
BENCHMARK(CodecDecodeSequential)->Unit(benchmark::kMillisecond);
BENCHMARK(CodecDecodeScan)->Unit(benchmark::kMillisecond);

void CodecMeasureError(benchmark::State& state) {
  const Tractogram& t = benchPhantom();
  const CodecParams params = chooseCodecParams(t);
  const EncodedFiblets f = encodeTractogram(t, params);
  const FibletDecoder decoder(params);
  for (auto _ : state) {
    const CodecErrorStats s = measureCodecError(t, f, decoder);
    benchmark::DoNotOptimize(s.max_um);
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(t.pointCount()));
}
BENCHMARK(CodecMeasureError)->Unit(benchmark::kMillisecond);

void CodecEncodeThreads(benchmark::State& state) {
  const Tractogram& t = benchPhantom();
  const CodecParams params = chooseCodecParams(t);
  const auto threads = unsigned(state.range(0));
  // Chunks of 200 fibers, as the compressor hands them out.
  std::vector<Tractogram> chunks;
  for (size_t s = 0; s < t.streamlineCount(); s += 200) {
    Tractogram c;
    for (size_t i = s; i < std::min(s + 200, t.streamlineCount()); ++i)
      c.addStreamline(t.point(t.offsets[i]), t.pointsIn(i));
    chunks.push_back(std::move(c));
  }
  std::vector<std::unique_ptr<FibletEncoder>> encoders;
  std::vector<CodecErrorMeter> meters(threads);
  for (unsigned w = 0; w < threads; ++w) {
    encoders.push_back(std::make_unique<FibletEncoder>(params));
    // As the compressor runs them: measuring every point.
    if (state.range(1)) encoders.back()->setErrorMeter(&meters[w]);
  }
  std::vector<EncodedFiblets> out(chunks.size());
  ThreadPool pool(threads);
  for (auto _ : state) {
    std::vector<std::future<void>> done;
    for (size_t c = 0; c < chunks.size(); ++c)
      done.push_back(pool.submit([&, c](unsigned w) {
        out[c].bytes.clear();
        out[c].fiber_first_fiblet.clear();
        out[c].fiber_points.clear();
        encoders[w]->encode(chunks[c], out[c]);
      }));
    for (auto& d : done) d.get();
  }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(t.pointCount()));
}
BENCHMARK(CodecEncodeThreads)
    ->ArgNames({"threads", "measure"})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({1, 1})
    ->Args({2, 1})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

void FblDecompressToPoints(benchmark::State& state) {
  static const std::string path = [] {
    const std::string p =
        std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") + "/fibscope_codec_bench.fbl";
    CompressOptions options;
    options.terminal_progress = false;
    options.overwrite = true;
    compressTractogram(
        [] {
          PhantomOptions o;
          o.streamlines = 2000;
          o.seed = 3;
          return openPhantom(o);
        },
        p, options);
    return p;
  }();
  const DecodeOrder order = state.range(0) ? DecodeOrder::Scan : DecodeOrder::Sequential;
  uint64_t points = 0;
  Tractogram chunk;
  for (auto _ : state) {
    auto reader = openFbl(path, order);
    while (reader->read(chunk)) {
      points += chunk.pointCount();
      benchmark::DoNotOptimize(chunk.positions.data());
    }
  }
  state.SetItemsProcessed(int64_t(points));
  state.SetLabel(order == DecodeOrder::Scan ? "scan" : "sequential");
}
BENCHMARK(FblDecompressToPoints)->ArgName("scan")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace fibscope

BENCHMARK_MAIN();
