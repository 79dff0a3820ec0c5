// GPU buffers: one VkBuffer with its own VkDeviceMemory (no sub-allocation
// yet: the renderer makes a few large buffers, not many small ones), always
// with a device address so that shaders reach them through buffer
// references in push constants (no descriptor sets, and no
// maxStorageBufferRange limit: lavapipe's is 128 MiB).
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>

#include "gpu/vulkan_context.h"

namespace fibscope::gpu {

enum class MemoryUse : uint8_t {
  DeviceLocal,  // GPU only; filled and read through staging copies
  Upload,       // host-visible, coherent, persistently mapped: CPU writes, GPU reads
  Readback,     // host-visible (cached where possible), mapped: GPU writes, CPU reads
};

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  VkDeviceAddress address = 0;  // for buffer references in shaders
  void* mapped = nullptr;       // Upload and Readback buffers
  bool coherent = false;        // mapped memory needs no flush/invalidate
  VkMemoryPropertyFlags memory_properties = 0;  // of the memory type chosen
};

// Memory of a type allowed by `requirements` with the properties `use`
// needs. Throws Error naming the size when no type fits or the allocation
// fails (out of memory is a user-visible condition, not a bug).
VkDeviceMemory allocateMemory(const VulkanContext& context, const VkMemoryRequirements& requirements, MemoryUse use,
                              bool device_address, VkMemoryPropertyFlags* properties = nullptr);

// A buffer of `size` bytes (> 0) usable as storage, transfer source and
// destination and by device address, plus `extra_usage` (e.g. indirect
// arguments). Throws Error when size exceeds the device's largest
// allocation or memory runs out.
Buffer createBuffer(const VulkanContext& context, VkDeviceSize size, MemoryUse use, VkBufferUsageFlags extra_usage = 0);
// For filling a DeviceLocal buffer the GPU has not used yet, or reading
// one after the GPU is done with it, without a staging copy: where the
// device shares the host's memory (a CPU device such as lavapipe, or an
// integrated GPU) and the buffer's memory is host-visible and coherent,
// maps it and returns the pointer (unmapBuffer when done; writes need no
// flush and are visible to later submissions); nullptr otherwise. Discrete
// GPUs keep the DMA copy: reaching device memory over the bus from the CPU
// is slower than the copy engine.
void* mapForDirectAccess(const VulkanContext& context, const Buffer& buffer);
void unmapBuffer(const VulkanContext& context, const Buffer& buffer);

// Destroys and resets `buffer`; a default Buffer is a no-op.
void destroyBuffer(const VulkanContext& context, Buffer& buffer);

// Copies bytes into / out of the buffer at `offset` (offset + bytes <=
// size): by memcpy for mapped buffers, through a temporary staging buffer
// and a one-shot copy for device-local ones (a download from a device that
// shares the host's memory maps the buffer instead, after a barrier that
// makes every earlier submission's writes visible to the host). The GPU
// must not be using the range (the staging copy waits for the queue to
// finish).
void uploadToBuffer(const VulkanContext& context, const Buffer& buffer, const void* data, size_t bytes,
                    VkDeviceSize offset = 0);
void downloadFromBuffer(const VulkanContext& context, const Buffer& buffer, void* data, size_t bytes,
                        VkDeviceSize offset = 0);

}  // namespace fibscope::gpu
