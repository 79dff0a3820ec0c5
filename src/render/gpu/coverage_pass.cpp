#include "render/gpu/coverage_pass.h"

#include <array>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "gpu/pass_scope.h"
#include "shared/coverage_push.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

// |P[1][1]| * height / 2, as cullFocalPixels.
float focalPixels(const Camera& camera) {
  const std::array<double, 16> projection = projectionMatrixD(camera);
  return float(std::abs(projection[5]) * 0.5 * double(camera.height));
}

}  // namespace

gpu::ComputePipeline createCoveragePipeline(const gpu::VulkanContext& context) {
  return gpu::createComputePipeline(context, "coverage_reproject.comp", sizeof(shader::CoverageReprojectPush),
                                    gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
}

void prepareCoverageHistory(const gpu::VulkanContext& context, CoverageHistory& history, uint32_t width,
                            uint32_t height) {
  const VkDeviceSize bytes = VkDeviceSize(shader::visibilityKeyCount(width, height)) * sizeof(uint64_t);
  if (history.previous_keys.buffer && history.previous_keys.size == bytes && history.camera.width == width &&
      history.camera.height == height)
    return;
  destroyCoverageHistory(context, history);
  history.previous_keys = gpu::createBuffer(context, bytes, gpu::MemoryUse::DeviceLocal);
  history.camera.width = width;
  history.camera.height = height;
}

void destroyCoverageHistory(const gpu::VulkanContext& context, CoverageHistory& history) {
  gpu::destroyBuffer(context, history.previous_keys);
  history = CoverageHistory{};
}

float coverageSplatRadiusMm(const Camera& camera, float view_depth_mm, float splat_pixels) {
  return shader::coverageSplatRadius(view_depth_mm, focalPixels(camera), splat_pixels);
}

void recordCoverageReproject(VkCommandBuffer cmd, const gpu::ComputePipeline& pipeline, const CoverageHistory& history,
                             const Camera& camera, const GpuFrameTargets& frame, VkDeviceAddress coverage,
                             float splat_pixels) {
  const std::array<double, 16> vp = viewProjectionD(history.camera);
  const glm::dmat4 inverse = glm::inverse(glm::make_mat4(vp.data()));  // column-major, as Mat4
  shader::CoverageReprojectPush push{};
  for (int c = 0; c < 4; ++c)
    push.previous_inverse_view_projection[c] =
        shader::vec4(float(inverse[c][0]), float(inverse[c][1]), float(inverse[c][2]), float(inverse[c][3]));
  push.previous = history.previous_keys.address;
  push.coverage = coverage;
  push.camera = frame.camera.address;
  push.width = frame.width;
  push.height = frame.height;
  push.previous_focal_px = focalPixels(history.camera);
  push.focal_px = focalPixels(camera);
  push.splat_pixels = splat_pixels;
  gpu::recordDispatch(cmd, pipeline, push, shader::pixelGroups(frame.width), shader::pixelGroups(frame.height));
}

}  // namespace fibscope
