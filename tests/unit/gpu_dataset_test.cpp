// GpuDataset (render/gpu/dataset.h): a compressed phantom uploaded from its
// .fbl (and from an in-memory encode) must land on the device byte for byte
// as the file's sections and the tables derived from them; a pass reading
// only through the FibletDataset block must decode every fiblet bit for bit
// like the CPU scan; a dataset too big for the device must fail with one
// line naming the file before anything is read. Validation layers on.
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "codec/compressor.h"
#include "codec/fbl_codec.h"
#include "codec/fbl_file.h"
#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "core/error.h"
#include "gpu/submit.h"
#include "gpu_test_context.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/gpu/dataset.h"
#include "shared/dataset_decode_push.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::TempDir;

constexpr uint64_t kStreamlines = 120;

std::unique_ptr<TractogramReader> phantomReader() {
  PhantomOptions options;
  options.streamlines = kStreamlines;
  options.step_mm = 0.1;
  options.seed = 11;
  options.threads = 1;
  return openPhantom(options);
}

std::string compressPhantom(const TempDir& dir, uint32_t n) {
  CompressOptions options;
  options.terminal_progress = false;
  options.threads = 1;
  options.params.points_per_fiblet = n;
  const std::string path = dir.file("phantom" + std::to_string(n) + ".fbl");
  compressTractogram(phantomReader, path, options);
  return path;
}

template <typename T>
std::vector<T> download(const gpu::VulkanContext& context, const gpu::Buffer& buffer, size_t count) {
  std::vector<T> values(count);
  gpu::downloadFromBuffer(context, buffer, values.data(), count * sizeof(T));
  return values;
}

template <typename T>
bool sameBytes(const std::vector<T>& a, std::span<const T> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

class GpuDatasetUpload : public test::GpuTest {
 protected:
  // Every buffer of `dataset` against `file`'s sections and the tables
  // derived from them, and the block's fields against the header.
  void expectMatchesFile(const GpuDataset& dataset, const FblFile& file) {
    const CodecParams params = codecParamsFromFbl(file.header(), file.path());
    const auto records = file.data(kFblSectionFiblets);
    const auto first = file.array<uint64_t>(*file.find(kFblSectionFiberFirstFiblet));
    const auto length = file.array<float>(*file.find(kFblSectionFiberLength));
    const size_t fibers = first.size() - 1, fiblets = records.size() / params.recordBytes();
    ASSERT_EQ(fibers, kStreamlines);

    const shader::FibletDataset& block = dataset.block();
    EXPECT_EQ(block.fiber_count, fibers);
    EXPECT_EQ(block.fiblet_count, fiblets);
    EXPECT_EQ(block.record_words, params.recordBytes() / 4);
    EXPECT_EQ(block.points_per_fiblet, params.points_per_fiblet);
    EXPECT_EQ(block.translation_x, params.translation[0]);
    EXPECT_EQ(block.translation_y, params.translation[1]);
    EXPECT_EQ(block.translation_z, params.translation[2]);
    EXPECT_EQ(block.mm_per_unit, float(1.0 / double(params.scale)));
    EXPECT_EQ(block.delta, params.delta);
    EXPECT_EQ(block.v_x, params.v[0]);
    EXPECT_EQ(block.v_y, params.v[1]);
    EXPECT_EQ(block.v_z, params.v[2]);
    EXPECT_EQ(block.records, dataset.records().address);
    EXPECT_EQ(block.fiblet_fiber, dataset.fibletFiber().address);
    EXPECT_EQ(block.directions, dataset.directions().address);
    EXPECT_EQ(block.fiber_first_fiblet, dataset.fiberFirstFiblet().address);
    EXPECT_EQ(block.fiber_length_mm, dataset.fiberLength().address);
    // The spheres are filled when the occlusion cull first needs them.
    EXPECT_EQ(block.fiblet_bounds, 0u);
    EXPECT_FALSE(dataset.fibletBoundsReady());

    EXPECT_TRUE(sameBytes(download<uint8_t>(context(), dataset.records(), records.size()), records))
        << "records differ from the fiblets section";
    std::vector<uint32_t> first32(first.begin(), first.end());
    EXPECT_EQ(download<uint32_t>(context(), dataset.fiberFirstFiblet(), fibers + 1), first32);
    EXPECT_TRUE(sameBytes(download<float>(context(), dataset.fiberLength(), fibers), length))
        << "fiber lengths differ from the fiber_length_mm section";
    const FibletDirectionTable table = buildDirectionTable(params.alpha);
    const auto directions = download<shader::vec4>(context(), dataset.directions(), 4 * table.size());
    EXPECT_EQ(std::memcmp(directions.data(), table.data(), sizeof table), 0) << "direction table differs";
    // Then each code's local transform, 12 floats in 3 vec4, bit for bit
    // the decoders' fibletLocalTransform.
    for (size_t code = 0; code < table.size(); ++code) {
      const shader::vec3 d(table[code].x, table[code].y, table[code].z);
      const shader::FibletTransform l = shader::fibletLocalTransform(d, shader::vec3(block.v_x, block.v_y, block.v_z),
                                                                     block.delta);
      const float expected[12] = {l.c0.x, l.c0.y, l.c0.z, l.c1.x, l.c1.y, l.c1.z,
                                  l.c2.x, l.c2.y, l.c2.z, l.t.x,  l.t.y,  l.t.z};
      ASSERT_EQ(std::memcmp(&directions[table.size() + 3 * code], expected, sizeof expected), 0) << "L of code " << code;
    }
    const auto uploaded_block = download<shader::FibletDataset>(context(), dataset.blockBuffer(), 1);
    EXPECT_EQ(std::memcmp(&uploaded_block[0], &block, sizeof block), 0) << "block buffer differs from block()";

    // Fiber of every fiblet, against the ranges of fiber_first_fiblet.
    const auto fiblet_fiber = download<uint32_t>(context(), dataset.fibletFiber(), fiblets);
    size_t wrong = 0;
    for (size_t f = 0; f < fibers; ++f)
      for (uint64_t i = first[f]; i < first[f + 1]; ++i) wrong += fiblet_fiber[i] != f;
    EXPECT_EQ(wrong, 0u) << "of " << fiblets << " fiblets have the wrong fiber index";
    EXPECT_EQ(first[fibers], fiblets);

    EXPECT_EQ(dataset.bytes(), records.size() + 4 * fiblets + 4 * sizeof table + 4 * (fibers + 1) + 4 * fibers +
                                   sizeof(shader::FibletDataset) + 16 * fiblets);  // + the fiblet bounds
  }

  // Decodes every fiblet through the block; compares with decodeScan.
  void expectDecodesLikeTheCpuScan(const GpuDataset& dataset, const FblFile& file) {
    const CodecParams params = codecParamsFromFbl(file.header(), file.path());
    const uint32_t n = params.points_per_fiblet, record_bytes = params.recordBytes();
    const auto records = file.data(kFblSectionFiblets);
    const size_t fiblets = records.size() / record_bytes;
    gpu::Buffer& points = buffer(fiblets * 3 * n * sizeof(float), gpu::MemoryUse::DeviceLocal);
    gpu::Buffer& counts = buffer(fiblets * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    gpu::ComputePipeline& decode = pipeline("dataset_decode_test.comp", sizeof(shader::DatasetDecodePush));
    gpu::GpuTimer& gpu_timer = timer(1);
    shader::DatasetDecodePush push{};
    push.dataset = dataset.blockAddress();
    push.points = points.address;
    push.counts = counts.address;
    const gpu::DispatchGrid grid = gpu::dispatchGrid(context(), fiblets);
    gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
      gpu::resetGpuTimer(cmd, gpu_timer);
      gpu::beginPass(cmd, gpu_timer, "decode");
      gpu::recordDispatch(cmd, decode, push, grid.x, grid.y);
      gpu::endPass(cmd, gpu_timer);
    });
    const auto gpu_counts = download<uint32_t>(context(), counts, fiblets);
    const auto gpu_points = download<float>(context(), points, fiblets * 3 * n);

    const FibletDecoder decoder(params);
    std::vector<float> cpu(3 * n);
    size_t total = 0, mismatched = 0;
    for (size_t i = 0; i < fiblets; ++i) {
      const uint32_t count = decoder.decodeScan(records.data() + i * record_bytes, cpu.data());
      ASSERT_GE(count, 1u) << "fiblet " << i;
      ASSERT_EQ(gpu_counts[i], count) << "fiblet " << i;
      const float* g = gpu_points.data() + i * 3 * n;
      if (std::memcmp(g, cpu.data(), 3 * count * sizeof(float)) != 0 && mismatched++ < 5)
        for (uint32_t k = 0; k < 3 * count; ++k)
          if (std::bit_cast<uint32_t>(g[k]) != std::bit_cast<uint32_t>(cpu[k])) {
            ADD_FAILURE() << "fiblet " << i << " point " << k / 3 << " coordinate " << k % 3 << ": GPU " << g[k]
                          << ", CPU " << cpu[k];
            break;
          }
      total += count;
    }
    EXPECT_EQ(mismatched, 0u) << "of " << fiblets << " fiblets";
    EXPECT_EQ(total, file.header().point_count);
    std::printf("[ GPU      ] N = %u: %zu fiblets, %zu points decoded through the dataset block on %s; %.3f ms\n", n,
                fiblets, total, context().info().name.c_str(), gpu::readGpuTimer(context(), gpu_timer).at(0).ms);
  }

  TempDir dir_;
};

TEST_F(GpuDatasetUpload, uploadedBuffersEqualTheFileSectionsAndDerivedTables) {
  const FblFile file = FblFile::open(compressPhantom(dir_, 60));
  Progress progress("uploading", 0, "bytes", false);
  const auto start = std::chrono::steady_clock::now();
  const GpuDataset dataset = GpuDataset::upload(context(), file, &progress);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  expectMatchesFile(dataset, file);
  // Every byte uploaded; the bounds buffer is filled later, on the device.
  EXPECT_EQ(progress.snapshot().done, double(dataset.bytes() - dataset.fibletBounds().size));
  std::printf("[ GPU      ] uploaded %llu bytes in %.1f ms on %s\n", (unsigned long long)dataset.bytes(), ms,
              context().info().name.c_str());
}

TEST_F(GpuDatasetUpload, smallStagingBufferCopiesInManyChunksToTheSameBytes) {
  const FblFile file = FblFile::open(compressPhantom(dir_, 60));
  // 1000 bytes: chunk boundaries fall inside records and inside words
  // (where the device cannot take the bytes in place; on CPU and integrated
  // devices the same bytes land without staging: gpu_staged_upload_test).
  Progress progress("uploading", 0, "bytes", false);
  const GpuDataset dataset = GpuDataset::upload(context(), file, &progress, nullptr, 1000);
  ASSERT_GT(dataset.records().size, 100u * 1000u);
  expectMatchesFile(dataset, file);
  EXPECT_EQ(progress.snapshot().done, double(dataset.bytes() - dataset.fibletBounds().size));
}

TEST_F(GpuDatasetUpload, passReadingOnlyTheBlockDecodesBitForBitLikeTheCpuScan) {
  for (uint32_t n : {60u, 8u}) {
    SCOPED_TRACE("N = " + std::to_string(n));
    const FblFile file = FblFile::open(compressPhantom(dir_, n));
    const GpuDataset dataset = GpuDataset::upload(context(), file);
    expectDecodesLikeTheCpuScan(dataset, file);
  }
}

TEST_F(GpuDatasetUpload, encodedFibletsUploadEqualsTheFileUpload) {
  const FblFile file = FblFile::open(compressPhantom(dir_, 60));
  const CodecParams params = codecParamsFromFbl(file.header(), file.path());
  const Tractogram phantom = readAllStreamlines(*phantomReader());
  // Compression on the fly: the same parameters, encoded in memory.
  const EncodedFiblets encoded = encodeTractogram(phantom, params);
  ASSERT_TRUE(sameBytes(encoded.bytes, file.data(kFblSectionFiblets)))
      << "the in-memory encode differs from the compressor's";
  const auto length = file.array<float>(*file.find(kFblSectionFiberLength));
  const GpuDataset dataset = GpuDataset::upload(context(), encoded, params, length, "phantom (in memory)");
  expectMatchesFile(dataset, file);
}

TEST_F(GpuDatasetUpload, uploadInPartsEqualsTheFileUpload) {
  // Runs of whole fibers encoded apart, as `render` streams them, uploaded
  // without joining: the same device bytes as the file's sections. One part
  // is empty, and the part boundaries fall at odd fibers.
  const FblFile file = FblFile::open(compressPhantom(dir_, 60));
  const CodecParams params = codecParamsFromFbl(file.header(), file.path());
  const Tractogram phantom = readAllStreamlines(*phantomReader());
  std::vector<EncodedFiblets> parts;
  for (auto [begin, end] : {std::pair<size_t, size_t>{0, 7}, {7, 7}, {7, 61}, {61, kStreamlines}}) {
    Tractogram run;
    for (size_t s = begin; s < end; ++s) run.addStreamline(phantom.point(phantom.offsets[s]), phantom.pointsIn(s));
    parts.push_back(encodeTractogram(run, params));
  }
  std::vector<const EncodedFiblets*> list;
  for (const EncodedFiblets& part : parts) list.push_back(&part);
  const auto length = file.array<float>(*file.find(kFblSectionFiberLength));
  const GpuDataset dataset = GpuDataset::upload(context(), list, params, length, "phantom (in parts)");
  expectMatchesFile(dataset, file);
}

TEST_F(GpuDatasetUpload, datasetTooBigForTheDeviceFailsWithOneLineBeforeReadingAnything) {
  const std::string path = compressPhantom(dir_, 60);
  // Corrupt the fiblets section: reading it would fail its checksum, so
  // the size error below proves nothing was read (nor allocated: buffers
  // are created after the sections are read).
  uint64_t offset = 0;
  {
    const FblFile file = FblFile::open(path);
    offset = file.find(kFblSectionFiblets)->offset + 100;
  }
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(std::streamoff(offset));
    char byte = 0;
    f.read(&byte, 1);
    byte = char(byte ^ 0x5a);
    f.seekp(std::streamoff(offset));
    f.write(&byte, 1);
  }
  const FblFile file = FblFile::open(path);

  DeviceLimits small;
  small.device_name = "tinygpu";
  small.device_local_heap_bytes = 16 << 10;
  small.max_allocation_bytes = 1 << 20;
  small.max_buffer_bytes = 1 << 20;
  try {
    GpuDataset::upload(context(), file, nullptr, &small);
    FAIL() << "a dataset larger than the heap was uploaded";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find("do not fit on tinygpu"), std::string::npos) << what;
    EXPECT_NE(what.find("device-local heap 16.00 KiB"), std::string::npos) << what;
    EXPECT_NE(what.find("streaming is not implemented yet"), std::string::npos) << what;
    EXPECT_EQ(what.find("one buffer"), std::string::npos) << what;
    std::printf("[ GPU      ] %s\n", what.c_str());
  }

  // The heap is large enough, one buffer is not.
  DeviceLimits one_buffer = small;
  one_buffer.device_local_heap_bytes = uint64_t(1) << 40;
  one_buffer.max_allocation_bytes = 4096;
  try {
    GpuDataset::upload(context(), file, nullptr, &one_buffer);
    FAIL() << "a dataset with a buffer above the largest allocation was uploaded";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_NE(what.find("the fiblet records need one buffer of"), std::string::npos) << what;
    EXPECT_NE(what.find("largest allocation 4.00 KiB"), std::string::npos) << what;
  }

  // With the device's own limits the same file gets past the size check
  // and fails on the corrupted section instead.
  try {
    GpuDataset::upload(context(), file);
    FAIL() << "a corrupted fiblets section was uploaded";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_EQ(what.find("do not fit"), std::string::npos) << what;
  }
}

TEST_F(GpuDatasetUpload, fiberTablesThatDoNotCoverTheFibletsAreRefused) {
  const FblFile file = FblFile::open(compressPhantom(dir_, 60));
  const CodecParams params = codecParamsFromFbl(file.header(), file.path());
  EncodedFiblets encoded;
  encoded.record_bytes = params.recordBytes();
  const auto records = file.data(kFblSectionFiblets);
  encoded.bytes.assign(records.begin(), records.end());
  const auto first = file.array<uint64_t>(*file.find(kFblSectionFiberFirstFiblet));
  encoded.fiber_first_fiblet.assign(first.begin(), first.end() - 1);
  std::swap(encoded.fiber_first_fiblet[3], encoded.fiber_first_fiblet[4]);  // decreasing
  const std::vector<float> length(encoded.fiber_first_fiblet.size(), 1.0f);
  EXPECT_THROW(
      {
        try {
          GpuDataset::upload(context(), encoded, params, length, "swapped");
        } catch (const Error& e) {
          EXPECT_EQ(std::string(e.what()).rfind("swapped: fiber_first_fiblet decreases at fiber", 0), 0u) << e.what();
          throw;
        }
      },
      Error);
  // An entry beyond the fiblets, the order restored after it: refused
  // before the per-fiblet table is filled past its end.
  std::swap(encoded.fiber_first_fiblet[3], encoded.fiber_first_fiblet[4]);
  encoded.fiber_first_fiblet[2] = 1u << 30;
  try {
    GpuDataset::upload(context(), encoded, params, length, "beyond");
    ADD_FAILURE() << "a fiber table beyond the fiblets was uploaded";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("beyond: fiber_first_fiblet[2] is 1073741824, beyond the fiblet count", 0),
              0u)
        << e.what();
  }
  const std::vector<float> short_length(3, 1.0f);
  EXPECT_THROW(GpuDataset::upload(context(), encoded, params, short_length, "short"), Error);
}

TEST_F(GpuDatasetUpload, movedDatasetOwnsTheBuffersOnce) {
  const FblFile file = FblFile::open(compressPhantom(dir_, 60));
  GpuDataset a = GpuDataset::upload(context(), file);
  const uint64_t bytes = a.bytes();
  const VkDeviceAddress address = a.blockAddress();
  GpuDataset b(std::move(a));
  EXPECT_EQ(a.bytes(), 0u);
  EXPECT_EQ(b.bytes(), bytes);
  EXPECT_EQ(b.blockAddress(), address);
  GpuDataset c;
  c = std::move(b);
  EXPECT_EQ(b.bytes(), 0u);
  EXPECT_EQ(c.bytes(), bytes);
  c = GpuDataset::upload(context(), file);  // frees the first upload's buffers
  expectMatchesFile(c, file);
}

}  // namespace
}  // namespace fibscope
