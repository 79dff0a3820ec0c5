#include "render/gpu/pick.h"

#include <cmath>
#include <numbers>
#include <string>

#include "core/error.h"
#include "gpu/submit.h"
#include "shared/render_config.h"

namespace fibscope {

gpu::Buffer createPickBuffer(const gpu::VulkanContext& context) {
  return gpu::createBuffer(context, kPickBufferBytes, gpu::MemoryUse::Readback);
}

void recordPickReadback(VkCommandBuffer cmd, const GpuFrameTargets& targets, uint32_t x, uint32_t y,
                        const gpu::Buffer& host_dst) {
  if (host_dst.buffer == VK_NULL_HANDLE || !host_dst.mapped || host_dst.size < kPickBufferBytes)
    fail("pick", "the read-back buffer must be host-visible and hold at least " + std::to_string(kPickBufferBytes) +
                     " bytes, got " + std::to_string(host_dst.size));
  const bool inside = x < targets.width && y < targets.height && targets.gbuffer.buffer != VK_NULL_HANDLE &&
                      targets.gbuffer.size >= targets.pixels() * sizeof(shader::GBufferTexel);
  if (inside) {
    // Every pipeline's last G-buffer write is a compute store (resolve) or a
    // transfer (the lines pipeline copies its attachment in): wait for all
    // of them.
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    const VkBufferCopy copy{(uint64_t(y) * targets.width + x) * sizeof(shader::GBufferTexel), 0, kPickBufferBytes};
    vkCmdCopyBuffer(cmd, targets.gbuffer.buffer, host_dst.buffer, 1, &copy);
  } else {
    // No texel there: an all-ones texel (fiber = kNoFiberId) decodes as no hit.
    static_assert(shader::kNoFiberId == 0xFFFFFFFFu, "the fill pattern is the no-fiber id");
    vkCmdFillBuffer(cmd, host_dst.buffer, 0, kPickBufferBytes, 0xFFFFFFFFu);
  }
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

PickResult decodePick(const shader::GBufferTexel& texel) {
  PickResult result;
  if (texel.fiber == shader::kNoFiberId) return result;
  result.hit = true;
  result.fiber = texel.fiber;
  result.segment = texel.segment;
  result.depth = texel.depth;
  result.surface = (texel.segment & shader::kGBufferSurface) != 0;
  if (result.surface) result.source = texel.segment & ~shader::kGBufferSurface;
  return result;
}

PickResult readPick(const gpu::VulkanContext& context, const gpu::Buffer& host_dst) {
  shader::GBufferTexel texel{};
  gpu::downloadFromBuffer(context, host_dst, &texel, sizeof texel);  // invalidates non-coherent memory
  return decodePick(texel);
}

PickResult pickFiber(const gpu::VulkanContext& context, const GpuFrameTargets& targets, uint32_t x, uint32_t y) {
  gpu::Buffer buffer = createPickBuffer(context);
  try {
    gpu::submitOnce(context, [&](VkCommandBuffer cmd) { recordPickReadback(cmd, targets, x, y, buffer); });
    const PickResult result = readPick(context, buffer);
    gpu::destroyBuffer(context, buffer);
    return result;
  } catch (...) {
    gpu::destroyBuffer(context, buffer);
    throw;
  }
}

std::optional<Vec3d> unprojectPixel(const Camera& camera, double x, double y, double depth) {
  if (!(depth >= 0 && depth < 1) || !std::isfinite(x) || !std::isfinite(y)) return std::nullopt;
  try {
    validateCamera(camera);
  } catch (const Error&) {
    return std::nullopt;
  }
  // The rows of viewMatrixD are s, u, -f (camera.cpp); view space looks down -z.
  const std::array<double, 16> view = viewMatrixD(camera);
  const Vec3d s = {view[0], view[4], view[8]}, u = {view[1], view[5], view[9]}, back = {view[2], view[6], view[10]};
  const double n = camera.near_mm, f = camera.far_mm;
  // projectionMatrixD: z_clip = A z + B, w_clip = -z, depth = z_clip / w_clip
  // => z = -B / (A + depth).
  const double a = f / (n - f), b = n * f / (n - f);
  const double z = -b / (a + depth);
  const double g = 1.0 / std::tan(camera.fov_y_deg * std::numbers::pi / 360.0);
  const double aspect = double(camera.width) / double(camera.height);
  const double x_ndc = 2 * (x + 0.5) / camera.width - 1, y_ndc = 2 * (y + 0.5) / camera.height - 1;
  // x_ndc = (g / aspect) x_view / -z;  y_ndc = -g y_view / -z (y down).
  const double xv = x_ndc * -z * aspect / g, yv = -y_ndc * -z / g;
  Vec3d world;
  for (int k = 0; k < 3; ++k) world[k] = camera.eye[k] + s[k] * xv + u[k] * yv + back[k] * z;
  return world;
}

}  // namespace fibscope
