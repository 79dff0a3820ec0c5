// Uploads into device buffers (render/gpu/staged_upload.h): through a
// small staging buffer in many chunks, and in place where the device shares
// the host's memory (lavapipe here), with the range spread over threads.
// Either way the buffer must hold the source's bytes exactly, every byte
// counted once in the progress. Validation layers on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <utility>
#include <vector>

#include "core/thread_pool.h"
#include "gpu_test_context.h"
#include "render/gpu/staged_upload.h"

namespace fibscope {
namespace {

using GpuStagedUpload = test::GpuTest;

// Bytes no two offsets share within 2^32: a misplaced chunk shows.
std::vector<uint8_t> pattern(size_t n) {
  std::vector<uint8_t> bytes(n);
  for (size_t i = 0; i < n; ++i) bytes[i] = uint8_t((i * 2654435761u) >> 13);
  return bytes;
}

std::vector<uint8_t> download(const gpu::VulkanContext& context, const gpu::Buffer& buffer, size_t n) {
  std::vector<uint8_t> bytes(n);
  gpu::downloadFromBuffer(context, buffer, bytes.data(), n);
  return bytes;
}

TEST_F(GpuStagedUpload, smallStagingBufferCopiesInManyChunksToTheSameBytes) {
  const std::vector<uint8_t> source = pattern(300001);
  gpu::Buffer& staging = buffer(1000, gpu::MemoryUse::Upload);
  gpu::Buffer& destination = buffer(source.size() + 64, gpu::MemoryUse::DeviceLocal);
  Progress progress("uploading", 0, "bytes", false);
  uploadChunked(context(), staging, destination, source.size(), bytesOf(source.data()), &progress, 64);
  const std::vector<uint8_t> got = download(context(), destination, source.size() + 64);
  EXPECT_TRUE(std::equal(source.begin(), source.end(), got.begin() + 64)) << "bytes differ after the offset";
  EXPECT_EQ(progress.snapshot().done, double(source.size()));
}

TEST_F(GpuStagedUpload, inPlaceOnASharedMemoryDeviceSpreadOverThreadsWithoutStaging) {
  const VkPhysicalDeviceType type = context().info().type;
  if (type != VK_PHYSICAL_DEVICE_TYPE_CPU && type != VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU)
    GTEST_SKIP() << context().info().name << " does not share the host's memory: uploads go through staging";
  // 70 MiB + 3: two rounds of 64 MiB, pieces of odd sizes.
  const size_t n = (size_t(70) << 20) + 3;
  const std::vector<uint8_t> source = pattern(n);
  gpu::Buffer& destination = buffer(n, gpu::MemoryUse::DeviceLocal);
  std::mutex mutex;
  std::vector<std::pair<uint64_t, uint64_t>> ranges;
  const ChunkSource copy = bytesOf(source.data());
  const ChunkSource recording = [&](uint8_t* out, uint64_t offset, uint64_t bytes) {
    {
      std::lock_guard lock(mutex);
      ranges.emplace_back(offset, bytes);
    }
    copy(out, offset, bytes);
  };
  bool staged = false;
  gpu::Buffer unused;
  Progress progress("uploading", 0, "bytes", false);
  uploadRandomAccess(
      context(),
      [&]() -> const gpu::Buffer& {
        staged = true;
        return unused;
      },
      destination, n, recording, &progress);
  EXPECT_FALSE(staged) << "asked for a staging buffer";
  EXPECT_TRUE(download(context(), destination, n) == source) << "bytes differ";
  EXPECT_EQ(progress.snapshot().done, double(n));
  // The ranges tile [0, n) exactly, in more than one piece per round where
  // there are threads to spread over.
  std::sort(ranges.begin(), ranges.end());
  uint64_t next = 0;
  for (const auto& [offset, bytes] : ranges) {
    EXPECT_EQ(offset, next);
    next = offset + bytes;
  }
  EXPECT_EQ(next, n);
  if (ThreadPool::hardwareThreads() > 1) {
    EXPECT_GT(ranges.size(), 2u);
  }
}

TEST_F(GpuStagedUpload, bufferThatCannotBeWrittenInPlaceGoesThroughStaging) {
  // An Upload buffer is mapped already: never mapped a second time, so the
  // copy takes the staged path (the one of discrete GPUs).
  const std::vector<uint8_t> source = pattern(50000);
  gpu::Buffer& destination = buffer(source.size(), gpu::MemoryUse::Upload);
  gpu::Buffer& staging = buffer(4096, gpu::MemoryUse::Upload);
  int staged = 0;
  uploadRandomAccess(
      context(),
      [&]() -> const gpu::Buffer& {
        ++staged;
        return staging;
      },
      destination, source.size(), bytesOf(source.data()), nullptr);
  EXPECT_EQ(staged, 1);
  EXPECT_TRUE(download(context(), destination, source.size()) == source) << "bytes differ";
}

}  // namespace
}  // namespace fibscope
