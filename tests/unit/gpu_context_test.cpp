// The Vulkan layer on whatever device runs the tests (lavapipe on CI):
// device choice, buffers reached through device addresses, images, timestamp
// queries, and that the validation layer really reports misuse (so that the
// zero-error check of every GPU test means something).
#include <gtest/gtest.h>

#include <link.h>

#include <algorithm>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "gpu/leak_check_pins.h"
#include "gpu/submit.h"
#include "gpu_test_context.h"
#include "test_support.h"

namespace fibscope {
namespace {

class GpuContext : public test::GpuTest {};

TEST_F(GpuContext, choosesAUsableDeviceAndFindsItByName) {
  const auto& devices = context().instance().devices();
  ASSERT_FALSE(devices.empty());
  const gpu::DeviceInfo& chosen = context().info();
  EXPECT_TRUE(chosen.missing.empty()) << chosen.missing;
  EXPECT_GE(chosen.api_version, VK_API_VERSION_1_3);
  EXPECT_GT(chosen.subgroup_size, 0u);
  EXPECT_TRUE(chosen.buffer_device_address && chosen.shader_int64 && chosen.buffer_int64_atomics);
  // No usable device ranks above the chosen one.
  for (const gpu::DeviceInfo& d : devices) {
    if (d.missing.empty() && d.type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU) {
      EXPECT_EQ(chosen.type, VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU) << d.name << " was passed over";
    }
  }
  // By name, case-insensitively, and a name that matches nothing lists the devices.
  std::string upper = chosen.name;
  for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(&gpu::chooseDevice(devices, upper), &gpu::chooseDevice(devices, chosen.name));
  try {
    gpu::chooseDevice(devices, "no-such-device-anywhere");
    ADD_FAILURE() << "an unknown device name was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("no-such-device-anywhere"), std::string::npos) << message;
    EXPECT_NE(message.find(chosen.name), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST_F(GpuContext, unusableDevicesAreRefusedWithWhatTheyLack) {
  gpu::DeviceInfo old = context().info();
  old.name = "Old GPU";
  old.missing = "no shaderBufferInt64Atomics";
  const std::vector<gpu::DeviceInfo> only_old = {old};
  try {
    gpu::chooseDevice(only_old, "");
    ADD_FAILURE() << "an unusable device was chosen";
  } catch (const gpu::VulkanUnavailable& e) {
    EXPECT_NE(std::string(e.what()).find("Old GPU: no shaderBufferInt64Atomics"), std::string::npos) << e.what();
  }
  EXPECT_THROW(gpu::chooseDevice(only_old, "old"), Error);
}

TEST_F(GpuContext, bufferRoundTripsThroughAShaderByDeviceAddress) {
  constexpr uint32_t kCount = 100000;  // not a multiple of the workgroup size
  std::vector<uint32_t> input(kCount);
  std::iota(input.begin(), input.end(), 7u);
  gpu::Buffer& src = buffer(kCount * 4, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& dst = buffer(kCount * 4, gpu::MemoryUse::DeviceLocal);
  ASSERT_NE(src.address, 0u);
  ASSERT_NE(src.address, dst.address);
  gpu::uploadToBuffer(context(), src, input.data(), kCount * 4);
  // The plain staging round trip first.
  std::vector<uint32_t> back(kCount);
  gpu::downloadFromBuffer(context(), src, back.data(), kCount * 4);
  ASSERT_EQ(back, input);

  struct Push {
    uint64_t src, dst;
    uint32_t count, pad;
  } push{src.address, dst.address, kCount, 0};
  gpu::ComputePipeline& copy = pipeline("buffer_copy_test.comp", sizeof push);
  gpu::submitOnce(context(), [&](VkCommandBuffer cmd) { gpu::recordDispatch(cmd, copy, push, (kCount + 63) / 64); });
  gpu::downloadFromBuffer(context(), dst, back.data(), kCount * 4);
  for (uint32_t i = 0; i < kCount; ++i) ASSERT_EQ(back[i], input[i] * 3 + 1) << "element " << i;

  // A range check, not a crash, for a download past the end.
  EXPECT_THROW(gpu::downloadFromBuffer(context(), dst, back.data(), 8, kCount * 4 - 4), Error);
}

TEST_F(GpuContext, mappedBuffersNeedNoStaging) {
  gpu::Buffer& upload = buffer(256, gpu::MemoryUse::Upload);
  gpu::Buffer& readback = buffer(256, gpu::MemoryUse::Readback);
  ASSERT_NE(upload.mapped, nullptr);
  ASSERT_NE(readback.mapped, nullptr);
  std::vector<uint8_t> bytes(256), back(256);
  std::iota(bytes.begin(), bytes.end(), uint8_t(0));
  gpu::uploadToBuffer(context(), upload, bytes.data(), bytes.size());
  gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
    const VkBufferCopy region{0, 0, 256};
    vkCmdCopyBuffer(cmd, upload.buffer, readback.buffer, 1, &region);
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                       VK_ACCESS_2_HOST_READ_BIT);
  });
  gpu::downloadFromBuffer(context(), readback, back.data(), back.size());
  EXPECT_EQ(back, bytes);
}

TEST_F(GpuContext, clearedImageDownloadsAsRgba8) {
  gpu::Image& img =
      image(37, 5, VK_FORMAT_B8G8R8A8_UNORM, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
    gpu::transitionImage(cmd, img, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                         VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkClearColorValue colour{};
    colour.float32[0] = 1.0f;  // red
    colour.float32[1] = 0.0f;
    colour.float32[2] = 0.25f;  // blue: 0.25 * 255 = 63.75 -> 64
    colour.float32[3] = 1.0f;
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &colour, 1, &range);
  });
  const std::vector<uint8_t> pixels = gpu::downloadImageRgba8(context(), img);
  ASSERT_EQ(pixels.size(), 37u * 5 * 4);
  for (size_t i = 0; i < pixels.size(); i += 4) {
    ASSERT_EQ(pixels[i], 255) << "pixel " << i / 4;
    ASSERT_EQ(pixels[i + 1], 0);
    ASSERT_EQ(pixels[i + 2], 64);
    ASSERT_EQ(pixels[i + 3], 255);
  }
}

TEST_F(GpuContext, graphicsPipelineDrawsATriangleWithDynamicRendering) {
  // Clip space (-1,-1) is the top-left corner in Vulkan: the triangle covers
  // the pixels above the anti-diagonal, i.e. centres with x + y < size.
  constexpr uint32_t kSize = 64;
  const float positions[] = {-1, -1, 1, -1, -1, 1};
  gpu::Buffer& vertices = buffer(sizeof positions, gpu::MemoryUse::Upload);
  gpu::uploadToBuffer(context(), vertices, positions, sizeof positions);
  struct Push {
    uint64_t positions;
    float r, g, b, a;
  } push{vertices.address, 0.0f, 1.0f, 0.0f, 1.0f};
  gpu::GraphicsPipelineDesc desc;
  desc.vertex_shader = "triangle_test.vert";
  desc.fragment_shader = "triangle_test.frag";
  desc.push_constant_bytes = sizeof push;
  gpu::GraphicsPipeline& triangle = graphicsPipeline(desc);
  gpu::Image& target = image(kSize, kSize, VK_FORMAT_R8G8B8A8_UNORM,
                             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
  ASSERT_NE(target.view, VK_NULL_HANDLE);
  gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
    gpu::beginRendering(cmd, target, VkClearColorValue{{0.0f, 0.0f, 1.0f, 1.0f}});
    gpu::recordDraw(cmd, triangle, push, 3);
    gpu::endRendering(cmd);
  });
  const std::vector<uint8_t> pixels = gpu::downloadImageRgba8(context(), target);
  uint32_t green = 0, blue = 0;
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      const uint8_t* p = &pixels[4 * (y * kSize + x)];
      const bool is_green = p[0] == 0 && p[1] == 255 && p[2] == 0 && p[3] == 255;
      const bool is_blue = p[0] == 0 && p[1] == 0 && p[2] == 255 && p[3] == 255;
      ASSERT_TRUE(is_green || is_blue) << "pixel " << x << ", " << y;
      // Centres exactly on the diagonal (x + y + 1 == size) go by the
      // fill rule; everything else is decided.
      if (x + y + 1 < kSize) {
        EXPECT_TRUE(is_green) << "pixel " << x << ", " << y;
      } else if (x + y + 1 > kSize) {
        EXPECT_TRUE(is_blue) << "pixel " << x << ", " << y;
      }
      green += is_green;
      blue += is_blue;
    }
  EXPECT_GE(green, kSize * (kSize - 1) / 2);
  EXPECT_GE(blue, kSize * (kSize - 1) / 2);
}

TEST_F(GpuContext, timestampQueriesMeasureAPositiveTimePerPass) {
  constexpr uint32_t kCount = 1 << 20;
  gpu::Buffer& src = buffer(kCount * 4, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& dst = buffer(kCount * 4, gpu::MemoryUse::DeviceLocal);
  struct Push {
    uint64_t src, dst;
    uint32_t count, pad;
  } push{src.address, dst.address, kCount, 0};
  gpu::ComputePipeline& copy = pipeline("buffer_copy_test.comp", sizeof push);
  gpu::GpuTimer& t = timer(2);
  gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, src.buffer, 0, VK_WHOLE_SIZE, 5);
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    gpu::resetGpuTimer(cmd, t);
    gpu::beginPass(cmd, t, "first");
    gpu::recordDispatch(cmd, copy, push, kCount / 64);
    gpu::endPass(cmd, t);
    gpu::beginPass(cmd, t, "second");
    gpu::recordDispatch(cmd, copy, push, kCount / 64);
    gpu::endPass(cmd, t);
  });
  const std::vector<gpu::PassTime> times = gpu::readGpuTimer(context(), t);
  ASSERT_EQ(times.size(), 2u);
  EXPECT_EQ(times[0].name, "first");
  EXPECT_EQ(times[1].name, "second");
  for (const gpu::PassTime& p : times) {
    EXPECT_GT(p.ms, 0.0) << p.name;
    EXPECT_LT(p.ms, 60000.0) << p.name;
  }
  uint32_t last = 0;
  gpu::downloadFromBuffer(context(), dst, &last, 4, (kCount - 1) * 4);
  EXPECT_EQ(last, 5u * 3 + 1);
}

TEST_F(GpuContext, validationLayerReportsADeliberateMisuse) {
  // A buffer with no usage flags breaks VUID-VkBufferCreateInfo-usage-
  // requiredbitmask; the driver itself does not mind, so nothing crashes.
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = 64;
  info.usage = 0;
  VkBuffer bad = VK_NULL_HANDLE;
  if (vkCreateBuffer(context().device(), &info, nullptr, &bad) == VK_SUCCESS)
    vkDestroyBuffer(context().device(), bad, nullptr);
  ASSERT_GE(log().errors(), 1) << "the validation layer is not active";
  bool named = false;
  for (const std::string& m : log().messages()) named |= m.find("VkBufferCreateInfo-usage") != std::string::npos;
  EXPECT_TRUE(named) << "the error does not name the broken rule";
  log().clear();  // provoked on purpose: not a failure of this test
}

TEST_F(GpuContext, synchronisationValidationReportsAMissingBarrier) {
  // A fill and a copy out of the filled buffer with no barrier between them:
  // a read-after-write hazard that only synchronisation validation sees.
  // (It tracks transfers and descriptor-bound resources; shader accesses
  // through buffer device addresses are invisible to it, so barriers
  // between compute passes can only be tested through their results.)
  gpu::Buffer& src = buffer(1024, gpu::MemoryUse::DeviceLocal);
  gpu::Buffer& dst = buffer(1024, gpu::MemoryUse::DeviceLocal);
  gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
    vkCmdFillBuffer(cmd, src.buffer, 0, VK_WHOLE_SIZE, 1);
    const VkBufferCopy region{0, 0, 1024};
    vkCmdCopyBuffer(cmd, src.buffer, dst.buffer, 1, &region);
  });
  bool hazard = false;
  for (const std::string& m : log().messages()) hazard |= m.find("SYNC-HAZARD-READ") != std::string::npos;
  EXPECT_TRUE(hazard) << "synchronisation validation is not active";
  log().clear();  // provoked on purpose
}

// The shared libraries mapped into this process now, by path.
std::set<std::string> loadedLibraries() {
  std::set<std::string> names;
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void* out) {
        if (info->dlpi_name && info->dlpi_name[0] != '\0')
          static_cast<std::set<std::string>*>(out)->insert(info->dlpi_name);
        return 0;
      },
      &names);
  return names;
}

TEST(GpuLeakCheckPins, theDriverStaysMappedAfterItsInstanceInLeakCheckedBuilds) {
  // Under LeakSanitizer an unloaded driver's per-process allocations look
  // leaked from an "<unknown module>" (gpu/leak_check_pins.h); the instance
  // keeps every library it loaded mapped past vkDestroyInstance there.
  if (!gpu::leakChecksPinLibraries()) GTEST_SKIP() << "only builds with AddressSanitizer pin the driver";
  std::set<std::string> during;
  try {
    gpu::VulkanInstance instance(gpu::InstanceOptions{});
    during = loadedLibraries();
  } catch (const gpu::VulkanUnavailable& e) {
    GTEST_SKIP() << "no Vulkan driver: " << e.what();
  }
  const std::set<std::string> after = loadedLibraries();
  std::vector<std::string> unloaded;
  std::set_difference(during.begin(), during.end(), after.begin(), after.end(), std::back_inserter(unloaded));
  EXPECT_TRUE(unloaded.empty()) << "unloaded with the instance: " << unloaded.front();
}

TEST(GpuInfoCommand, missingVulkanDriverIsOneClearLine) {
  // Point the loader at a driver list that does not exist.
  const test::CommandResult r = test::runCommand(
      "VK_DRIVER_FILES=/nonexistent/icd.json VK_ICD_FILENAMES=/nonexistent/icd.json " FIBSCOPE_EXE " gpu-info 2>&1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(r.output, "fibscope: error: vulkan: no Vulkan driver found (install mesa-vulkan-drivers)\n");
}

TEST(GpuInfoCommand, unknownDeviceNameIsOneClearLine) {
  const test::CommandResult r = test::runCommand(FIBSCOPE_EXE " gpu-info --device no-such-device-anywhere 2>&1");
  if (r.output.find("no Vulkan driver found") != std::string::npos) GTEST_SKIP() << "no Vulkan driver";
  EXPECT_EQ(r.exit_code, 2) << r.output;
  // The device list comes first, then the error as the last line.
  const std::string error = "fibscope: error: vulkan: no device name contains \"no-such-device-anywhere\"";
  const size_t at = r.output.find(error);
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_EQ(r.output.find('\n', at), r.output.size() - 1) << r.output;
}

}  // namespace
}  // namespace fibscope
