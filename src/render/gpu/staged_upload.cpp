#include "render/gpu/staged_upload.h"

#include <algorithm>
#include <cstring>

#include "core/thread_pool.h"

#include "gpu/submit.h"
#include "gpu/vk_check.h"

namespace fibscope {

ChunkSource bytesOf(const void* data) {
  return [data](uint8_t* out, uint64_t offset, uint64_t bytes) {
    std::memcpy(out, static_cast<const uint8_t*>(data) + offset, size_t(bytes));
  };
}

void uploadChunked(const gpu::VulkanContext& context, const gpu::Buffer& staging, const gpu::Buffer& destination,
                   uint64_t bytes, const ChunkSource& source, Progress* progress, uint64_t destination_offset) {
  for (uint64_t offset = 0; offset < bytes;) {
    const uint64_t chunk = std::min<uint64_t>(staging.size, bytes - offset);
    source(static_cast<uint8_t*>(staging.mapped), offset, chunk);
    if (!staging.coherent) {
      VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
      range.memory = staging.memory;
      range.size = VK_WHOLE_SIZE;
      VK_CHECK(vkFlushMappedMemoryRanges(context.device(), 1, &range));
    }
    gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
      const VkBufferCopy copy{0, destination_offset + offset, chunk};
      vkCmdCopyBuffer(cmd, staging.buffer, destination.buffer, 1, &copy);
      // The fence orders the host only: make the copy visible to every
      // later command on the queue (compute, vertex pulling, indirect reads).
      gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                         VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
    });
    offset += chunk;
    if (progress) progress->add(double(chunk));
  }
}

void uploadRandomAccess(const gpu::VulkanContext& context, const std::function<const gpu::Buffer&()>& staging,
                        const gpu::Buffer& destination, uint64_t bytes, const ChunkSource& source, Progress* progress) {
  if (bytes == 0) return;
  uint8_t* mapped = static_cast<uint8_t*>(gpu::mapForDirectAccess(context, destination));
  if (!mapped) {
    uploadChunked(context, staging(), destination, bytes, source, progress);
    return;
  }
  constexpr uint64_t kRound = uint64_t(64) << 20;  // progress steps
  constexpr uint64_t kMinPiece = uint64_t(4) << 20;  // smaller is not worth a thread
  try {
    for (uint64_t round = 0; round < bytes; round += kRound) {
      const uint64_t round_bytes = std::min(kRound, bytes - round);
      const unsigned pieces =
          unsigned(std::clamp<uint64_t>(round_bytes / kMinPiece, 1, ThreadPool::hardwareThreads()));
      const uint64_t piece = (round_bytes + pieces - 1) / pieces;
      runPieces(pieces, [&](unsigned i) {
        const uint64_t begin = round + i * piece;
        if (begin < round + round_bytes) source(mapped + begin, begin, std::min(piece, round + round_bytes - begin));
      });
      if (progress) progress->add(double(round_bytes));
    }
  } catch (...) {
    gpu::unmapBuffer(context, destination);
    throw;
  }
  gpu::unmapBuffer(context, destination);
}

}  // namespace fibscope
