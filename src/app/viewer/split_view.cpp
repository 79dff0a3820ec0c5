#include "app/viewer/split_view.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "gpu/submit.h"

namespace fibscope {

double splitDistanceFactor(const Bounds& framed, const Bounds& shown) {
  const double ratio = boundingRadius(shown) / boundingRadius(framed);
  return kSplitDistanceFactor * (std::isfinite(ratio) ? std::max(ratio, 1.0) : 1.0);
}

Camera splitHalfCamera(const Camera& camera, bool right, double distance_factor, const Bounds& shown) {
  Camera half = camera;
  const uint32_t left = splitLeftWidth(camera.width);
  half.width = std::max(1u, right ? camera.width - left : left);
  double distance2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double back = camera.eye[k] - camera.target[k];
    half.eye[k] = camera.target[k] + distance_factor * back;
    distance2 += back * back;
  }
  // Everything the full camera's planes enclosed lies that much farther now.
  const double distance = std::sqrt(distance2), shift = distance * (distance_factor - 1);
  half.near_mm += shift;
  half.far_mm += shift;
  // And the union's box, which may reach beyond the box the camera was
  // framed on.
  return enclosingDepthRange(half, boundsCorners(shown));
}

void recordSplitCompose(VkCommandBuffer cmd, const gpu::Buffer& left, const gpu::Buffer& right,
                        const gpu::Buffer& out, uint32_t width, uint32_t height) {
  // The shade passes wrote the halves from a compute shader.
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  const uint32_t left_width = splitLeftWidth(width), right_width = width - left_width;
  // One region a row: the halves' rows are shorter than the output's.
  std::vector<VkBufferCopy> regions(height);
  for (const bool is_right : {false, true}) {
    const uint32_t w = is_right ? right_width : left_width;
    if (w == 0) continue;
    for (uint32_t y = 0; y < height; ++y)
      regions[y] = {uint64_t(y) * w * 4, (uint64_t(y) * width + (is_right ? left_width : 0)) * 4, uint64_t(w) * 4};
    vkCmdCopyBuffer(cmd, (is_right ? right : left).buffer, out.buffer, height, regions.data());
  }
  // Read next by a copy (into the presentation image or a download buffer);
  // compute too, for a reader that samples it.
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
}

}  // namespace fibscope
