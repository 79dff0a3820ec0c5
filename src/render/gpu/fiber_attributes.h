// Per-fiber attributes the shading reads through GpuScene (DESIGN.md
// section 6, "Shading"): a float per fiber for ColorMode::Scalar and the
// selection as one bit per fiber, in small device-local buffers sized for
// one dataset and filled through a staging copy.
//
// Fiber ids are the G-buffer's (the streamline index in the drawn
// tractogram), so the buffers belong to one dataset: make new ones when
// another is drawn.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"

namespace fibscope {

// uint32 words of a selection of `fibers` fibers (bit f % 32 of word f / 32).
inline uint64_t selectionWordCount(uint64_t fibers) { return (fibers + 31) / 32; }

class GpuFiberAttributes {
 public:
  GpuFiberAttributes() = default;
  // Buffers for `fiber_count` fibers (> 0; < 2^32, as the shaders index
  // fibers with uint), nothing uploaded yet. Throws Error when memory runs
  // out.
  GpuFiberAttributes(const gpu::VulkanContext& context, uint64_t fiber_count);
  ~GpuFiberAttributes();
  GpuFiberAttributes(GpuFiberAttributes&& other) noexcept;
  GpuFiberAttributes& operator=(GpuFiberAttributes&& other) noexcept;
  GpuFiberAttributes(const GpuFiberAttributes&) = delete;
  GpuFiberAttributes& operator=(const GpuFiberAttributes&) = delete;

  // Replace the scalars (exactly fiber_count values) / the selection
  // (exactly selectionWordCount(fiber_count) words, e.g.
  // FiberSelection::bitWords; bits past the last fiber must be 0). Each
  // waits for the queue (a staging copy): call between frames, after the
  // last frame that read the buffer has completed. Throws Error for a wrong
  // count or set bits past the end.
  void uploadScalars(std::span<const float> values);
  void uploadSelection(std::span<const uint32_t> words);
  // Forget them (no GPU work): the addresses become 0.
  void clearScalars() { has_scalars_ = false; }
  void clearSelection() { selected_ = 0; }

  // For GpuScene: 0 before an upload, after a clear, and (selection) when
  // no bit is set, so an empty selection dims nothing.
  VkDeviceAddress scalars() const { return has_scalars_ ? scalars_.address : 0; }
  VkDeviceAddress selection() const { return selected_ > 0 ? selection_.address : 0; }

  uint64_t fiberCount() const { return fiber_count_; }
  uint64_t selectedCount() const { return selected_; }

 private:
  void release();

  const gpu::VulkanContext* context_ = nullptr;
  uint64_t fiber_count_ = 0;
  gpu::Buffer scalars_, selection_;
  bool has_scalars_ = false;
  uint64_t selected_ = 0;  // set bits in the uploaded words
};

}  // namespace fibscope
