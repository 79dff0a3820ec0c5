#include "render/gpu/scene_table.h"

#include <cstring>
#include <string>

#include "core/error.h"
#include "gpu/submit.h"
#include "shared/render_config.h"

namespace fibscope {

SceneLayout sceneLayout(std::span<const GpuDataset* const> datasets) {
  if (datasets.size() > shader::kMaxSceneDatasets)
    throw Error("render: a scene draws at most " + std::to_string(shader::kMaxSceneDatasets) + " models, got " +
                std::to_string(datasets.size()));
  SceneLayout layout;
  uint64_t fiblets = 0, fibers = 0;
  for (const GpuDataset* dataset : datasets) {
    layout.entries.push_back({dataset, uint32_t(fiblets), uint32_t(fibers), dataset->blockAddress(),
                              dataset->block().fiblet_count, dataset->block().fiber_count});
    fiblets += dataset->block().fiblet_count;
    fibers += dataset->block().fiber_count;
    // Checked per step: the bases of the next dataset must fit too.
    if (fiblets > shader::kMaxFiblets)
      throw Error("render: the visible models hold " + std::to_string(fiblets) + " fiblets or more, above the " +
                  std::to_string(shader::kMaxFiblets) +
                  " one frame can address (28 bits of the visibility key); hide a model");
    if (fibers >= shader::kNoFiberId)
      throw Error("render: the visible models hold " + std::to_string(fibers) +
                  " fibers or more, above the 2^32 - 2 one frame can address; hide a model");
  }
  layout.fiblets = uint32_t(fiblets);
  layout.fibers = uint32_t(fibers);
  return layout;
}

std::optional<SceneFiber> locateSceneFiber(const SceneLayout& layout, uint32_t global_fiber) {
  if (global_fiber >= layout.fibers) return std::nullopt;
  // The last entry starting at or before the fiber that holds fibers (an
  // empty dataset shares its base with the next one).
  for (size_t i = layout.entries.size(); i-- > 0;) {
    const SceneEntry& e = layout.entries[i];
    if (e.fiber_base <= global_fiber && global_fiber - e.fiber_base < e.fibers)
      return SceneFiber{uint32_t(i), global_fiber - e.fiber_base};
  }
  return std::nullopt;
}

bool sameScene(const SceneLayout& a, const SceneLayout& b) {
  if (a.entries.size() != b.entries.size() || a.fiblets != b.fiblets || a.fibers != b.fibers) return false;
  for (size_t i = 0; i < a.entries.size(); ++i) {
    const SceneEntry& x = a.entries[i];
    const SceneEntry& y = b.entries[i];
    if (x.block != y.block || x.fiblets != y.fiblets || x.fibers != y.fibers) return false;
  }
  return true;
}

std::vector<uint32_t> sceneTableWords(const SceneLayout& layout) {
  shader::SceneTableHeader header{};
  header.count = uint32_t(layout.entries.size());
  header.fiblet_count = layout.fiblets;
  header.fiber_count = layout.fibers;
  std::vector<uint32_t> words((sizeof(header) + layout.entries.size() * sizeof(shader::SceneDataset)) / 4);
  std::memcpy(words.data(), &header, sizeof(header));
  for (size_t i = 0; i < layout.entries.size(); ++i) {
    shader::SceneDataset entry{};
    entry.block = layout.entries[i].block;
    entry.fiblet_base = layout.entries[i].fiblet_base;
    entry.fiber_base = layout.entries[i].fiber_base;
    std::memcpy(reinterpret_cast<char*>(words.data()) + sizeof(header) + i * sizeof(entry), &entry, sizeof(entry));
  }
  return words;
}

gpu::Buffer createSceneTableBuffer(const gpu::VulkanContext& context) {
  return gpu::createBuffer(context,
                           sizeof(shader::SceneTableHeader) + shader::kMaxSceneDatasets * sizeof(shader::SceneDataset),
                           gpu::MemoryUse::DeviceLocal);
}

void recordSceneTableUpdate(VkCommandBuffer cmd, const gpu::Buffer& table, const SceneLayout& layout) {
  const std::vector<uint32_t> words = sceneTableWords(layout);
  vkCmdUpdateBuffer(cmd, table.buffer, 0, words.size() * sizeof(uint32_t), words.data());
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
}

GpuSceneFiberLengths::~GpuSceneFiberLengths() { gpu::destroyBuffer(*context_, concatenated_); }

VkDeviceAddress GpuSceneFiberLengths::update(const SceneLayout& layout) {
  if (layout.fibers == 0) return address_ = 0;
  if (layout.entries.size() == 1) return address_ = layout.entries[0].dataset->fiberLength().address;
  if (address_ != 0 && address_ == concatenated_.address && sameScene(layout, for_)) return address_;
  const VkDeviceSize bytes = VkDeviceSize(layout.fibers) * sizeof(float);
  if (concatenated_.size < bytes) {
    vkDeviceWaitIdle(context_->device());  // earlier frames may read it
    gpu::destroyBuffer(*context_, concatenated_);
    address_ = 0;
    concatenated_ = gpu::createBuffer(*context_, bytes, gpu::MemoryUse::DeviceLocal);
  }
  gpu::submitOnce(*context_, [&](VkCommandBuffer cmd) {
    for (const SceneEntry& e : layout.entries) {
      const uint32_t fibers = e.dataset->block().fiber_count;
      if (fibers == 0) continue;
      const VkBufferCopy region{0, VkDeviceSize(e.fiber_base) * sizeof(float), VkDeviceSize(fibers) * sizeof(float)};
      vkCmdCopyBuffer(cmd, e.dataset->fiberLength().buffer, concatenated_.buffer, 1, &region);
    }
  });
  for_ = layout;
  return address_ = concatenated_.address;
}

}  // namespace fibscope
