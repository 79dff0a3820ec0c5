// Surfaces: the spline tubes by adaptive tessellation (tube_tess_stage.h):
// the keys draw, then the texels draw of the same pipeline.
#include "tubes/gpu/tube_tess_stage.h"

#include <algorithm>
#include <string>

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu/graphics_pipeline.h"
#include "gpu/pass_scope.h"
#include "gpu/tessellation_draws.h"
#include "shared/tube_tess.h"
#include "shared/tubes.h"

namespace fibscope {
namespace {

constexpr VkPipelineStageFlags2 kDrawStages =
    VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT |
    VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;

class TubeTessStage final : public FrameStage {
 public:
  TubeTessStage(const GpuTubes* tubes, TubeTessOptions options) : tubes_(tubes), options_(options) {}
  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyBuffer(context, keys_);
    gpu::destroyGraphicsPipeline(context, pipeline_);
  }
  uint32_t maxPasses() const override { return 2; }
  bool runs(const FrameContext&) const override { return tubes_ && tubes_->segment_count > 0; }
  bool drawsSurfaces() const override { return true; }
  void check(const FrameContext& frame) const override { validate(frame.context, frame.settings); }
  // Validates and makes the pipeline for the settings' sample count now
  // (the method stage of tube_stage.cpp forwards prepare, not check).
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    validate(context, settings);
    ensurePipeline(context, sampleCount(settings));
  }
  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override { gpu::destroyBuffer(context, keys_); }
  void collect(const gpu::VulkanContext&, FrameStats& stats) override { stats.tube_method_bytes = keys_.size; }

  void record(FrameContext& frame) override {
    // Again here, before any command: the method-switching stage
    // (tube_stage.cpp) does not forward check().
    validate(frame.context, frame.settings);
    const uint32_t samples = sampleCount(frame.settings);
    ensurePipeline(frame.context, samples);
    if (keys_.buffer && keys_samples_ != samples) {
      vkDeviceWaitIdle(frame.context.device());  // earlier frames may still use them
      gpu::destroyBuffer(frame.context, keys_);
    }
    const uint32_t width = frame.targets.width, height = frame.targets.height;
    if (!keys_.buffer) {
      keys_ = gpu::createBuffer(frame.context, frame.targets.pixels() * samples * sizeof(uint64_t),
                                gpu::MemoryUse::DeviceLocal);
      keys_samples_ = samples;
    }
    // The previous frame's texels draw read the keys before they are cleared.
    gpu::recordBarrier(frame.cmd,
                       {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdFillBuffer(frame.cmd, keys_.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
    // The clear, the camera block and the surface target the earlier
    // stages wrote (transfer or compute), before the draws' shaders.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                   VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, kDrawStages,
                                   gpu::kStorageReadWrite});
    shader::TubeTessPush push{};
    push.camera = frame.targets.camera.address;
    push.nodes = tubes_->nodes.address;
    push.segments = tubes_->segments.address;
    push.visibility = keys_.address;
    push.surface = frame.targets.surface.address;
    push.width = width;
    push.rings = uint32_t(std::clamp(frame.settings.tube_rings, 1, 64));
    push.vertices = uint32_t(std::clamp(frame.settings.tube_vertices, 3, 64));
    push.segment_count = tubes_->segment_count;
    push.samples = samples;
    push.flags = (options_.back_patch_culling ? shader::kTubeTessFlagBackCulling : 0u) |
                 (options_.frustum_culling ? shader::kTubeTessFlagFrustumCulling : 0u);
    const uint32_t patches = tubes_->segment_count * shader::tubeTessPatchesPerSegment(push.rings, push.vertices);
    const uint32_t per_draw = gpu::tessellationPatchesPerDraw(frame.context);
    const auto draw = [&](uint32_t mode) {
      push.mode = mode;
      gpu::beginRenderingWithoutAttachments(frame.cmd, width, height);
      vkCmdBindPipeline(frame.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_.pipeline);
      vkCmdPushConstants(frame.cmd, pipeline_.layout, pipeline_.stages, 0, sizeof(push), &push);
      gpu::recordPatchDraws(frame.cmd, 0, patches, per_draw);
      gpu::endRendering(frame.cmd);
    };
    {
      // The keys complete before the texels draw compares them.
      gpu::PassScope pass(frame.cmd, frame.timer, "tube tess",
                          {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, gpu::kStorageReadWrite,
                           VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, gpu::kStorageReadWrite});
      draw(shader::kTubeTessModeKeys);
    }
    {
      // The surface texels before the merge (compute) or another surface.
      gpu::PassScope pass(
          frame.cmd, frame.timer, "tube tess texels",
          {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, gpu::kStorageReadWrite,
           VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, gpu::kStorageReadWrite});
      draw(shader::kTubeTessModeTexels);
    }
  }

 private:
  // Throws Error naming what the device lacks for these settings.
  void validate(const gpu::VulkanContext& c, const RenderSettings& settings) const {
    const auto refuse = [&](const std::string& what) {
      throw Error("tubes: tessellated tubes need " + what + ", which " + c.info().name + " lacks");
    };
    if (!c.info().queue_has_graphics) refuse("a graphics queue");
    if (!c.enabledFeatures().tessellationShader) refuse("tessellation shaders (tessellationShader)");
    if (!c.enabledFeatures().fragmentStoresAndAtomics) refuse("fragmentStoresAndAtomics");
    const uint32_t samples = sampleCount(settings);
    if (samples == 0 || (c.limits().framebufferNoAttachmentsSampleCounts & samples) == 0)
      refuse("tube-msaa " + std::to_string(settings.tube_msaa) +
             " (samples per pixel without attachments, framebufferNoAttachmentsSampleCounts)");
    const uint64_t patches = uint64_t(tubes_ ? tubes_->segment_count : 0) * patchesPerSegment(settings);
    if (patches >= (uint64_t(1) << 32))
      throw Error("tubes: " + std::to_string(tubes_->segment_count) + " segments of " +
                  std::to_string(patchesPerSegment(settings)) +
                  " patches each is more than the 2^32 - 1 patches one tessellated frame numbers (fewer rings or "
                  "vertices)");
  }
  // The pipeline for `samples` (remade when the sample count changes).
  void ensurePipeline(const gpu::VulkanContext& context, uint32_t samples) {
    if (pipeline_.pipeline != VK_NULL_HANDLE && samples == samples_) return;
    if (pipeline_.pipeline != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(context.device());  // earlier frames may still use it
      gpu::destroyGraphicsPipeline(context, pipeline_);
    }
    gpu::GraphicsPipelineDesc desc;
    desc.vertex_shader = "tube_tess.vert";
    desc.tess_control_shader = "tube_tess.tesc";
    desc.tess_evaluation_shader = "tube_tess.tese";
    desc.fragment_shader = "tube_tess.frag";
    desc.topology = VK_PRIMITIVE_TOPOLOGY_PATCH_LIST;
    desc.patch_control_points = 1;
    desc.color_format = VK_FORMAT_UNDEFINED;
    desc.push_constant_bytes = sizeof(shader::TubeTessPush);
    desc.samples = VkSampleCountFlagBits(samples);
    pipeline_ = gpu::createGraphicsPipeline(context, desc);
    samples_ = samples;
  }
  // tube_msaa as a sample count (1, 4 or 8; 0 for anything else).
  static uint32_t sampleCount(const RenderSettings& s) {
    return s.tube_msaa == 1 || s.tube_msaa == 4 || s.tube_msaa == 8 ? uint32_t(s.tube_msaa) : 0u;
  }
  static uint32_t patchesPerSegment(const RenderSettings& s) {
    return shader::tubeTessPatchesPerSegment(uint32_t(std::clamp(s.tube_rings, 1, 64)),
                                             uint32_t(std::clamp(s.tube_vertices, 3, 64)));
  }

  const GpuTubes* tubes_;
  TubeTessOptions options_;
  gpu::GraphicsPipeline pipeline_;  // made at the first frame with tubes
  gpu::Buffer keys_;                // uint64_t visibility key per pixel (per sample), row-major
  uint32_t samples_ = 1;            // the pipeline's samples
  uint32_t keys_samples_ = 1;       // keys_'s keys per pixel
};

}  // namespace

FrameStageFactory tubeTessellationStage(const GpuTubes* tubes) { return tubeTessellationStage(tubes, {}); }

FrameStageFactory tubeTessellationStage(const GpuTubes* tubes, TubeTessOptions options) {
  return [tubes, options](const gpu::VulkanContext&) { return std::make_unique<TubeTessStage>(tubes, options); };
}

}  // namespace fibscope
