#include "gpu/buffer.h"

#include <cstring>

#include "core/huge_pages.h"
#include "gpu/submit.h"
#include "gpu/vk_check.h"

namespace fibscope::gpu {

namespace {

std::string mib(VkDeviceSize bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }

int findMemoryType(const VulkanContext& context, uint32_t type_bits, VkMemoryPropertyFlags required,
                   VkMemoryPropertyFlags preferred) {
  const VkPhysicalDeviceMemoryProperties& memory = context.memoryProperties();
  int fallback = -1;
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if (!(type_bits & (1u << i))) continue;
    const VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return int(i);
    if (fallback < 0) fallback = int(i);
  }
  return fallback;
}

void checkRange(const Buffer& buffer, size_t bytes, VkDeviceSize offset, const char* what) {
  if (offset > buffer.size || bytes > buffer.size - offset)
    throw Error(std::string("vulkan: ") + what + " of " + std::to_string(bytes) + " bytes at offset " +
                std::to_string(offset) + " outside a buffer of " + std::to_string(buffer.size) + " bytes");
}

}  // namespace

VkDeviceMemory allocateMemory(const VulkanContext& context, const VkMemoryRequirements& requirements, MemoryUse use,
                              bool device_address, VkMemoryPropertyFlags* properties) {
  VkMemoryPropertyFlags required = 0, preferred = 0;
  switch (use) {
    case MemoryUse::DeviceLocal:
      preferred = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
      break;
    case MemoryUse::Upload:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      break;
    case MemoryUse::Readback:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
      preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
      break;
  }
  const int type = findMemoryType(context, requirements.memoryTypeBits, required, preferred);
  if (type < 0)
    throw Error("vulkan: " + context.info().name + " has no memory type for a " + mib(requirements.size) + " buffer");
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  if (device_address) info.pNext = &flags;
  info.allocationSize = requirements.size;
  info.memoryTypeIndex = uint32_t(type);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  const VkResult r = vkAllocateMemory(context.device(), &info, nullptr, &memory);
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
    throw Error("vulkan: out of memory allocating " + mib(requirements.size) + " on " + context.info().name);
  throwIfFailed(r, "vkAllocateMemory");
  const VkMemoryPropertyFlags flags_of_type = context.memoryProperties().memoryTypes[type].propertyFlags;
  if (properties) *properties = flags_of_type;
  // On a CPU device (lavapipe) "device memory" is the process's own: large
  // buffers (visibility, G-buffer, tangent cache, datasets) would take one
  // page fault per 4 KiB on first use, about a fifth of the first frame of
  // a large tractogram. Transparent huge pages make that one per 2 MiB.
  if (context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU && (flags_of_type & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) &&
      requirements.size >= (VkDeviceSize(4) << 20)) {
    void* mapped = nullptr;
    if (vkMapMemory(context.device(), memory, 0, VK_WHOLE_SIZE, 0, &mapped) == VK_SUCCESS) {
      adviseHugePages(mapped, size_t(requirements.size));
      vkUnmapMemory(context.device(), memory);
    }
  }
  return memory;
}

Buffer createBuffer(const VulkanContext& context, VkDeviceSize size, MemoryUse use, VkBufferUsageFlags extra_usage) {
  if (size == 0) throw Error("vulkan: a buffer of 0 bytes");
  const uint64_t max_allocation = context.info().max_memory_allocation_size;
  if (max_allocation != 0 && size > max_allocation)
    throw Error("vulkan: a buffer of " + mib(size) + " exceeds the largest allocation of " + context.info().name +
                " (" + mib(max_allocation) + ")");
  Buffer buffer;
  buffer.size = size;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | extra_usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  throwIfFailed(vkCreateBuffer(context.device(), &info, nullptr, &buffer.buffer), "vkCreateBuffer");
  try {
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(context.device(), buffer.buffer, &requirements);
    VkMemoryPropertyFlags properties = 0;
    buffer.memory = allocateMemory(context, requirements, use, true, &properties);
    buffer.memory_properties = properties;
    VK_CHECK(vkBindBufferMemory(context.device(), buffer.buffer, buffer.memory, 0));
    if (use != MemoryUse::DeviceLocal) {
      throwIfFailed(vkMapMemory(context.device(), buffer.memory, 0, VK_WHOLE_SIZE, 0, &buffer.mapped), "vkMapMemory");
      buffer.coherent = properties & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    }
  } catch (...) {
    destroyBuffer(context, buffer);
    throw;
  }
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  address.buffer = buffer.buffer;
  buffer.address = vkGetBufferDeviceAddress(context.device(), &address);
  return buffer;
}

void* mapForDirectAccess(const VulkanContext& context, const Buffer& buffer) {
  const VkPhysicalDeviceType type = context.info().type;
  if (type != VK_PHYSICAL_DEVICE_TYPE_CPU && type != VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU) return nullptr;
  constexpr VkMemoryPropertyFlags kNeeded = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  if (buffer.memory == VK_NULL_HANDLE || buffer.mapped || (buffer.memory_properties & kNeeded) != kNeeded)
    return nullptr;
  void* mapped = nullptr;
  if (vkMapMemory(context.device(), buffer.memory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) return nullptr;
  return mapped;
}

void unmapBuffer(const VulkanContext& context, const Buffer& buffer) { vkUnmapMemory(context.device(), buffer.memory); }

void destroyBuffer(const VulkanContext& context, Buffer& buffer) {
  if (buffer.buffer != VK_NULL_HANDLE) vkDestroyBuffer(context.device(), buffer.buffer, nullptr);
  // Freeing mapped memory unmaps it.
  if (buffer.memory != VK_NULL_HANDLE) vkFreeMemory(context.device(), buffer.memory, nullptr);
  buffer = Buffer{};
}

void uploadToBuffer(const VulkanContext& context, const Buffer& buffer, const void* data, size_t bytes,
                    VkDeviceSize offset) {
  checkRange(buffer, bytes, offset, "upload");
  if (bytes == 0) return;
  if (buffer.mapped) {
    std::memcpy(static_cast<char*>(buffer.mapped) + offset, data, bytes);
    if (!buffer.coherent) {
      VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
      range.memory = buffer.memory;
      range.size = VK_WHOLE_SIZE;
      VK_CHECK(vkFlushMappedMemoryRanges(context.device(), 1, &range));
    }
    return;
  }
  Buffer staging = createBuffer(context, bytes, MemoryUse::Upload);
  try {
    std::memcpy(staging.mapped, data, bytes);
    submitOnce(context, [&](VkCommandBuffer cmd) {
      const VkBufferCopy copy{0, offset, bytes};
      vkCmdCopyBuffer(cmd, staging.buffer, buffer.buffer, 1, &copy);
      // Waiting on the fence orders the host, not later GPU work: make the
      // copy visible to every later command on the queue.
      memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                    VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    });
  } catch (...) {
    destroyBuffer(context, staging);
    throw;
  }
  destroyBuffer(context, staging);
}

void downloadFromBuffer(const VulkanContext& context, const Buffer& buffer, void* data, size_t bytes,
                        VkDeviceSize offset) {
  checkRange(buffer, bytes, offset, "download");
  if (bytes == 0) return;
  if (buffer.mapped) {
    if (!buffer.coherent) {
      VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
      range.memory = buffer.memory;
      range.size = VK_WHOLE_SIZE;
      VK_CHECK(vkInvalidateMappedMemoryRanges(context.device(), 1, &range));
    }
    std::memcpy(data, static_cast<const char*>(buffer.mapped) + offset, bytes);
    return;
  }
  if (void* direct = mapForDirectAccess(context, buffer)) {
    try {
      // A barrier's first scope is every command submitted before it.
      submitOnce(context, [&](VkCommandBuffer cmd) {
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
      });
    } catch (...) {
      unmapBuffer(context, buffer);
      throw;
    }
    std::memcpy(data, static_cast<const char*>(direct) + offset, bytes);
    unmapBuffer(context, buffer);
    return;
  }
  Buffer staging = createBuffer(context, bytes, MemoryUse::Readback);
  try {
    submitOnce(context, [&](VkCommandBuffer cmd) {
      const VkBufferCopy copy{offset, 0, bytes};
      vkCmdCopyBuffer(cmd, buffer.buffer, staging.buffer, 1, &copy);
      // Make the copy visible to the host read after the fence.
      memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                    VK_ACCESS_2_HOST_READ_BIT);
    });
    downloadFromBuffer(context, staging, data, bytes, 0);
  } catch (...) {
    destroyBuffer(context, staging);
    throw;
  }
  destroyBuffer(context, staging);
}

}  // namespace fibscope::gpu
