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
#include <benchmark/benchmark.h>

#include <array>

#include "codec/codec_error.h"
#include "codec/codec_params.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "phantom/phantom.h"

namespace fibscope {
namespace {

const Tractogram& benchPhantom() {
  static const Tractogram tractogram = [] {
    PhantomOptions options;
    options.streamlines = 2000;
    options.seed = 3;
    auto reader = openPhantom(options);
    Tractogram all, chunk;
    while (reader->read(chunk)) all.append(chunk);
    return all;
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

}  // namespace
}  // namespace fibscope

BENCHMARK_MAIN();
