#include "render/gpu/upscale_pass.h"

#include <string>

#include "core/error.h"
#include "shared/render_config.h"
#include "shared/upscale_push.h"

namespace fibscope {

UpscalePass createUpscalePass(const gpu::VulkanContext& context) {
  UpscalePass pass;
  pass.pipeline = gpu::createComputePipeline(context, "upscale_color.comp", sizeof(shader::UpscalePush),
                                             gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize});
  return pass;
}

void destroyUpscalePass(const gpu::VulkanContext& context, UpscalePass& pass) {
  gpu::destroyComputePipeline(context, pass.pipeline);
}

void recordUpscale(VkCommandBuffer cmd, const UpscalePass& pass, const gpu::Buffer& src, uint32_t src_width,
                   uint32_t src_height, const gpu::Buffer& dst, uint32_t dst_width, uint32_t dst_height) {
  if (src_width == 0 || src_height == 0 || dst_width == 0 || dst_height == 0)
    throw Error("upscale: empty image (" + std::to_string(src_width) + " x " + std::to_string(src_height) + " -> " +
                std::to_string(dst_width) + " x " + std::to_string(dst_height) + ")");
  if (src.size < uint64_t(src_width) * src_height * 4 || dst.size < uint64_t(dst_width) * dst_height * 4)
    throw Error("upscale: a colour buffer is smaller than its image");
  shader::UpscalePush push{};
  push.src = src.address;
  push.dst = dst.address;
  push.src_width = src_width;
  push.src_height = src_height;
  push.dst_width = dst_width;
  push.dst_height = dst_height;
  gpu::recordDispatch(cmd, pass.pipeline, push, shader::pixelGroups(dst_width), shader::pixelGroups(dst_height));
}

}  // namespace fibscope
