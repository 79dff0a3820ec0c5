#include "render/gpu/fiber_attributes.h"

#include <bit>
#include <string>
#include <utility>

#include "core/error.h"

namespace fibscope {

GpuFiberAttributes::GpuFiberAttributes(const gpu::VulkanContext& context, uint64_t fiber_count)
    : context_(&context), fiber_count_(fiber_count) {
  if (fiber_count == 0 || fiber_count >= (uint64_t(1) << 32))
    throw Error("fiber attributes: expected 1 to 2^32 - 1 fibers, got " + std::to_string(fiber_count));
  try {
    scalars_ = gpu::createBuffer(context, fiber_count * sizeof(float), gpu::MemoryUse::DeviceLocal);
    selection_ = gpu::createBuffer(context, selectionWordCount(fiber_count) * sizeof(uint32_t),
                                   gpu::MemoryUse::DeviceLocal);
  } catch (...) {
    release();
    throw;
  }
}

GpuFiberAttributes::~GpuFiberAttributes() { release(); }

GpuFiberAttributes::GpuFiberAttributes(GpuFiberAttributes&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)),
      fiber_count_(std::exchange(other.fiber_count_, 0)),
      scalars_(std::exchange(other.scalars_, {})),
      selection_(std::exchange(other.selection_, {})),
      has_scalars_(std::exchange(other.has_scalars_, false)),
      selected_(std::exchange(other.selected_, 0)) {}

GpuFiberAttributes& GpuFiberAttributes::operator=(GpuFiberAttributes&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    fiber_count_ = std::exchange(other.fiber_count_, 0);
    scalars_ = std::exchange(other.scalars_, {});
    selection_ = std::exchange(other.selection_, {});
    has_scalars_ = std::exchange(other.has_scalars_, false);
    selected_ = std::exchange(other.selected_, 0);
  }
  return *this;
}

void GpuFiberAttributes::release() {
  if (!context_) return;
  gpu::destroyBuffer(*context_, scalars_);
  gpu::destroyBuffer(*context_, selection_);
  has_scalars_ = false;
  selected_ = 0;
}

void GpuFiberAttributes::uploadScalars(std::span<const float> values) {
  if (!context_) throw Error("fiber attributes: upload to an empty attribute set");
  if (values.size() != fiber_count_)
    throw Error("fiber attributes: expected " + std::to_string(fiber_count_) + " scalars (one per fiber), got " +
                std::to_string(values.size()));
  gpu::uploadToBuffer(*context_, scalars_, values.data(), values.size_bytes());
  has_scalars_ = true;
}

void GpuFiberAttributes::uploadSelection(std::span<const uint32_t> words) {
  if (!context_) throw Error("fiber attributes: upload to an empty attribute set");
  const uint64_t expected = selectionWordCount(fiber_count_);
  if (words.size() != expected)
    throw Error("fiber attributes: expected " + std::to_string(expected) + " selection words for " +
                std::to_string(fiber_count_) + " fibers, got " + std::to_string(words.size()));
  // Bits past the last fiber would be harmless to the shader (it never sees
  // those ids) but mean the caller's words belong to another dataset.
  const uint32_t tail_bits = uint32_t(fiber_count_ % 32);
  if (tail_bits != 0 && (words.back() >> tail_bits) != 0)
    throw Error("fiber attributes: selection bits set past the last fiber (" + std::to_string(fiber_count_) +
                " fibers)");
  uint64_t selected = 0;
  for (uint32_t w : words) selected += uint64_t(std::popcount(w));
  gpu::uploadToBuffer(*context_, selection_, words.data(), words.size_bytes());
  selected_ = selected;
}

}  // namespace fibscope
