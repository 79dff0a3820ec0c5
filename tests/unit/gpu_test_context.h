// Fixture for GPU tests (ctest label gpu): a Vulkan context on the best
// device with the validation layers on. No Vulkan device: the test is
// skipped with the reason. Any validation error or warning fails the test,
// checked after every object (and the device) is destroyed, so leaks and
// bad teardown count too.
#pragma once

#include <gtest/gtest.h>

#include <deque>
#include <memory>
#include <string>

#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/gpu_timer.h"
#include "gpu/graphics_pipeline.h"
#include "gpu/image.h"
#include "gpu/leak_check_pins.h"
#include "gpu/vulkan_context.h"

namespace fibscope::test {

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    log_ = std::make_shared<gpu::DebugLog>(false);
    gpu::ContextOptions options;
    options.instance.validation = true;
    options.instance.log = log_;
    try {
      context_ = std::make_unique<gpu::VulkanContext>(options);
    } catch (const gpu::VulkanUnavailable& e) {
      GTEST_SKIP() << "no usable Vulkan device: " << e.what();
    }
    // Pinned in this process whatever the build (gpu/leak_check_pins.h):
    // the driver stays loaded across the tests of one run.
    gpu::pinLoadedLibraries();
  }

  void TearDown() override {
    // Skipped: the loader's own complaints about the missing driver are the
    // reason already given, not validation errors.
    if (!context_) return;
    for (auto& b : buffers_) gpu::destroyBuffer(*context_, b);
    for (auto& i : images_) gpu::destroyImage(*context_, i);
    for (auto& p : pipelines_) gpu::destroyComputePipeline(*context_, p);
    for (auto& t : timers_) gpu::destroyGpuTimer(*context_, t);
    for (auto& g : graphics_) gpu::destroyGraphicsPipeline(*context_, g);
    context_.reset();
    std::string messages;
    for (const std::string& m : log_->messages()) messages += "\n  " + m;
    EXPECT_EQ(log_->errors(), 0) << "validation errors:" << messages;
    EXPECT_EQ(log_->warnings(), 0) << "validation warnings:" << messages;
  }

  gpu::VulkanContext& context() { return *context_; }
  gpu::DebugLog& log() { return *log_; }

  // Resources owned by the fixture, destroyed before the device in TearDown
  // (also when an assertion ends the test early).
  gpu::Buffer& buffer(VkDeviceSize size, gpu::MemoryUse use) {
    return buffers_.emplace_back(gpu::createBuffer(*context_, size, use));
  }
  gpu::Image& image(uint32_t width, uint32_t height, VkFormat format, VkImageUsageFlags usage) {
    return images_.emplace_back(gpu::createImage2D(*context_, width, height, format, usage));
  }
  gpu::ComputePipeline& pipeline(const char* shader, uint32_t push_bytes) {
    return pipelines_.emplace_back(gpu::createComputePipeline(*context_, shader, push_bytes));
  }
  gpu::GpuTimer& timer(uint32_t passes) { return timers_.emplace_back(gpu::createGpuTimer(*context_, passes)); }
  gpu::GraphicsPipeline& graphicsPipeline(const gpu::GraphicsPipelineDesc& desc) {
    return graphics_.emplace_back(gpu::createGraphicsPipeline(*context_, desc));
  }

 private:
  std::shared_ptr<gpu::DebugLog> log_;
  std::unique_ptr<gpu::VulkanContext> context_;
  std::deque<gpu::Buffer> buffers_;
  std::deque<gpu::Image> images_;
  std::deque<gpu::ComputePipeline> pipelines_;
  std::deque<gpu::GpuTimer> timers_;
  std::deque<gpu::GraphicsPipeline> graphics_;
};

}  // namespace fibscope::test
