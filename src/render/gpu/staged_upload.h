// Filling device-local buffers through one bounded, host-visible staging
// buffer (a 10 GB section needs no 10 GB of host-visible memory): shared
// by the fiblet and the raw-vertex uploads.
#pragma once

#include <cstdint>
#include <functional>

#include "core/progress.h"
#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"

namespace fibscope {

// Writes `bytes` bytes starting at byte `offset` of the buffer's contents
// to `out` (chunks come in increasing order, back to back), so contents can
// be generated chunk by chunk instead of held whole in memory.
using ChunkSource = std::function<void(uint8_t* out, uint64_t offset, uint64_t bytes)>;

// A ChunkSource copying from `data` (which must outlive the upload).
ChunkSource bytesOf(const void* data);

// Copies `bytes` bytes produced by `source` to `destination` from byte
// `destination_offset` on, through `staging` (an Upload buffer), one
// staging-full at a time, each copy submitted and waited for, and made
// visible to every later command on the queue. `progress` (optional) counts
// the bytes. The source's offsets count from the start of its own bytes.
void uploadChunked(const gpu::VulkanContext& context, const gpu::Buffer& staging, const gpu::Buffer& destination,
                   uint64_t bytes, const ChunkSource& source, Progress* progress, uint64_t destination_offset = 0);

// As uploadChunked, for a source that may be asked for any range, in any
// order and from several threads at once (bytesOf is): where
// gpu::mapForDirectAccess maps `destination` (CPU and integrated devices),
// the source writes straight into it, each 64 MiB spread over the hardware
// threads (the first-touch page faults of the fresh memory too), with no
// staging copy and no submission; otherwise uploadChunked through the
// buffer `staging()` returns (so a caller can make it on first need).
// `destination` must not be in use by the GPU.
void uploadRandomAccess(const gpu::VulkanContext& context, const std::function<const gpu::Buffer&()>& staging,
                        const gpu::Buffer& destination, uint64_t bytes, const ChunkSource& source, Progress* progress);

}  // namespace fibscope
