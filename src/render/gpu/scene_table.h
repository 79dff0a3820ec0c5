// The scene-global numbering of a frame that draws several datasets
// (shaders/shared/scene_table.h): each drawn dataset's first fiblet and
// first fiber in the scene, the small device buffer the resolve reads them
// from, and the scene-wide per-fiber lengths the scalar colour mode reads.
//
// Dataset i of a scene gets fiblet_base_i and fiber_base_i, the prefix sums
// of the fiblet and fiber counts of the datasets before it (in the order
// given). Keys carry global fiblets, the G-buffer global fibers; one model
// alone has bases 0, so its ids are its own.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/dataset.h"
#include "shared/scene_table.h"

namespace fibscope {

struct SceneEntry {
  const GpuDataset* dataset = nullptr;
  uint32_t fiblet_base = 0;
  uint32_t fiber_base = 0;
  // Copied from the dataset when the layout was made, so a layout kept
  // after its datasets are gone (the two-phase history, a pick's frame)
  // still compares and maps ids without touching them.
  VkDeviceAddress block = 0;
  uint32_t fiblets = 0, fibers = 0;
};

struct SceneLayout {
  std::vector<SceneEntry> entries;  // in drawing order, bases increasing
  uint32_t fiblets = 0;             // the scene's totals
  uint32_t fibers = 0;
};

// The layout of `datasets` (none null). Throws Error (one line) for more
// than kMaxSceneDatasets datasets, more than kMaxFiblets (2^28) fiblets in
// all (the visibility key's fiblet bits), or 2^32 - 1 fibers or more in all
// (kNoFiberId marks empty texels).
SceneLayout sceneLayout(std::span<const GpuDataset* const> datasets);

// Which dataset (index into layout.entries) a global fiber belongs to, and
// its fiber there; nullopt for ids past the scene's fibers. Reads the
// entries' copies only.
struct SceneFiber {
  uint32_t dataset = 0;
  uint32_t fiber = 0;
};
std::optional<SceneFiber> locateSceneFiber(const SceneLayout& layout, uint32_t global_fiber);

// True when both layouts draw the same datasets (block addresses and
// counts) in the same order: the two-phase history and scene-wide buffers
// made for one stay valid for the other. Reads the entries' copies only
// (the datasets of either may be gone).
bool sameScene(const SceneLayout& a, const SceneLayout& b);

// The table as the shaders read it (header + entries), for
// vkCmdUpdateBuffer: at most 16 + 16 * kMaxSceneDatasets bytes.
std::vector<uint32_t> sceneTableWords(const SceneLayout& layout);
// A device buffer that holds the largest table.
gpu::Buffer createSceneTableBuffer(const gpu::VulkanContext& context);
// Records the table's upload (vkCmdUpdateBuffer) followed by a barrier to
// compute reads.
void recordSceneTableUpdate(VkCommandBuffer cmd, const gpu::Buffer& table, const SceneLayout& layout);

// The scene's fiber lengths (mm) as one float per global fiber, for
// GpuScene::fiber_scalars: with one dataset its own fiberLength buffer (no
// copy); with several, the datasets' buffers copied one after the other
// into a buffer of this object's, redone only when the scene changes.
class GpuSceneFiberLengths {
 public:
  explicit GpuSceneFiberLengths(const gpu::VulkanContext& context) : context_(&context) {}
  ~GpuSceneFiberLengths();
  GpuSceneFiberLengths(const GpuSceneFiberLengths&) = delete;
  GpuSceneFiberLengths& operator=(const GpuSceneFiberLengths&) = delete;

  // Between frames (it may wait for the queue): makes address() the
  // lengths of `layout`'s fibers. Throws Error when memory runs out.
  VkDeviceAddress update(const SceneLayout& layout);
  VkDeviceAddress address() const { return address_; }
  // The next update copies again (a model was reloaded: a new dataset may
  // reuse a destroyed one's address and counts).
  void invalidate() { for_ = {}; }

 private:
  const gpu::VulkanContext* context_;
  gpu::Buffer concatenated_;
  SceneLayout for_;
  VkDeviceAddress address_ = 0;
};

}  // namespace fibscope
