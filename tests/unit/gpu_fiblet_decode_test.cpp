// The GPU half of "CPU decode is bit-identical to GPU decode" (DESIGN.md
// section 5): phantom fiblets decoded by shaders/fiblet_decode_test.comp
// (one workgroup per fiblet, the log-step scan in shared memory) must equal
// FibletDecoder::decodeScan bit for bit, on whatever device runs the tests
// (lavapipe on CI), with the validation layers on.
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

#include "codec/codec_params.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "gpu/submit.h"
#include "gpu_test_context.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "shared/fiblet_decode_push.h"

namespace fibscope {
namespace {

using shader::FibletDecodePush;

Tractogram phantomTractogram() {
  PhantomOptions options;
  options.streamlines = 120;
  options.step_mm = 0.1;
  options.seed = 11;
  options.threads = 1;
  return readAllStreamlines(*openPhantom(options));
}

struct GpuDecoded {
  std::vector<uint32_t> counts;
  std::vector<float> points;  // 3 * N per fiblet
  double ms = 0;
};

class GpuFibletDecode : public test::GpuTest {
 protected:
  // Decodes every record of `records` (record_bytes each) on the GPU.
  GpuDecoded decodeOnGpu(const std::vector<uint8_t>& records, const CodecParams& params) {
    const uint32_t n = params.points_per_fiblet;
    const size_t fiblets = records.size() / params.recordBytes();
    const FibletDirectionTable table = buildDirectionTable(params.alpha);
    gpu::Buffer& record_buffer = buffer(records.size(), gpu::MemoryUse::DeviceLocal);
    gpu::Buffer& table_buffer = buffer(sizeof table, gpu::MemoryUse::DeviceLocal);
    gpu::Buffer& point_buffer = buffer(fiblets * 3 * n * sizeof(float), gpu::MemoryUse::DeviceLocal);
    gpu::Buffer& count_buffer = buffer(fiblets * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context(), record_buffer, records.data(), records.size());
    gpu::uploadToBuffer(context(), table_buffer, table.data(), sizeof table);
    gpu::ComputePipeline& decode = pipeline("fiblet_decode_test.comp", sizeof(FibletDecodePush));
    gpu::GpuTimer& gpu_timer = timer(1);

    FibletDecodePush push{};
    push.records = record_buffer.address;
    push.table = table_buffer.address;
    push.points = point_buffer.address;
    push.counts = count_buffer.address;
    push.v_x = params.v[0];
    push.v_y = params.v[1];
    push.v_z = params.v[2];
    push.delta = params.delta;
    push.points_per_fiblet = n;
    push.fiblet_count = uint32_t(fiblets);
    const gpu::DispatchGrid grid = gpu::dispatchGrid(context(), fiblets);
    gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
      gpu::resetGpuTimer(cmd, gpu_timer);
      gpu::beginPass(cmd, gpu_timer, "decode");
      gpu::recordDispatch(cmd, decode, push, grid.x, grid.y);
      gpu::endPass(cmd, gpu_timer);
    });

    GpuDecoded out;
    out.counts.resize(fiblets);
    out.points.resize(fiblets * 3 * n);
    gpu::downloadFromBuffer(context(), count_buffer, out.counts.data(), out.counts.size() * sizeof(uint32_t));
    gpu::downloadFromBuffer(context(), point_buffer, out.points.data(), out.points.size() * sizeof(float));
    out.ms = gpu::readGpuTimer(context(), gpu_timer).at(0).ms;
    return out;
  }

  void expectBitIdenticalToCpuScan(uint32_t n) {
    const Tractogram t = phantomTractogram();
    CodecParamOptions options;
    options.points_per_fiblet = n;
    const CodecParams params = chooseCodecParams(t, options);
    const EncodedFiblets encoded = encodeTractogram(t, params);
    ASSERT_GT(encoded.fibletCount(), 100u);

    // Besides the phantom's records, three that the decoder must refuse
    // (count 0, count N + 1, count 63) and one single-point fiblet.
    std::vector<uint8_t> records = encoded.bytes;
    const uint32_t record_bytes = params.recordBytes();
    const uint32_t flags_byte = shader::fibletFlagsByte(n);
    for (uint32_t count : {0u, n + 1, 63u, 1u}) {
      std::vector<uint8_t> extra(encoded.record(0), encoded.record(0) + record_bytes);
      extra[flags_byte] = uint8_t(shader::fibletFlags(true, true, count));
      records.insert(records.end(), extra.begin(), extra.end());
    }
    const size_t fiblets = records.size() / record_bytes;

    const GpuDecoded gpu = decodeOnGpu(records, params);
    const FibletDecoder decoder(params);
    std::vector<float> cpu(3 * n);
    size_t points = 0, mismatched_fiblets = 0;
    for (size_t i = 0; i < fiblets; ++i) {
      const uint32_t count = decoder.decodeScan(records.data() + i * record_bytes, cpu.data());
      ASSERT_EQ(gpu.counts[i], count) << "fiblet " << i;
      const float* g = gpu.points.data() + i * 3 * n;
      if (std::memcmp(g, cpu.data(), 3 * count * sizeof(float)) != 0) {
        if (mismatched_fiblets++ < 5)
          for (uint32_t k = 0; k < 3 * count; ++k)
            if (std::bit_cast<uint32_t>(g[k]) != std::bit_cast<uint32_t>(cpu[k])) {
              ADD_FAILURE() << "fiblet " << i << " point " << k / 3 << " coordinate " << k % 3 << ": GPU " << g[k]
                            << " (0x" << std::hex << std::bit_cast<uint32_t>(g[k]) << "), CPU " << std::dec << cpu[k]
                            << " (0x" << std::hex << std::bit_cast<uint32_t>(cpu[k]) << ")";
              break;
            }
      }
      points += count;
    }
    EXPECT_EQ(mismatched_fiblets, 0u) << "of " << fiblets << " fiblets";
    EXPECT_EQ(gpu.counts[fiblets - 1], 1u);
    std::printf("[ GPU      ] N = %u: %zu fiblets, %zu points bit-identical on %s; decode pass %.3f ms\n", n, fiblets,
                points, context().info().name.c_str(), gpu.ms);
  }
};

TEST_F(GpuFibletDecode, phantomFibletsOfSixtyPointsDecodeBitForBitLikeTheCpuScan) { expectBitIdenticalToCpuScan(60); }

TEST_F(GpuFibletDecode, phantomFibletsOfEightPointsDecodeBitForBitLikeTheCpuScan) { expectBitIdenticalToCpuScan(8); }

}  // namespace
}  // namespace fibscope
