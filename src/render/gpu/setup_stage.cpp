// The frame's first stage: what every later pass reads from the frame's
// start (the camera block, the compute pipeline's scene table) and the
// targets that passes accumulate into (the visibility buffer, the surface
// target), in one timed "clear" pass.
#include <bit>

#include "gpu/buffer.h"
#include "gpu/pass_scope.h"
#include "render/clip_planes.h"
#include "render/gpu/frame_stages.h"

namespace fibscope {
namespace {

class SetupStage final : public FrameStage {
 public:
  explicit SetupStage(const gpu::VulkanContext& context) : scene_table_(createSceneTableBuffer(context)) {}
  void destroy(const gpu::VulkanContext& context) override { gpu::destroyBuffer(context, scene_table_); }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext&) const override { return true; }

  void record(FrameContext& frame) override {
    const RenderPipeline pipeline = frame.settings.pipeline;
    // The graphics pipelines draw into depth attachments of their own.
    const bool graphics = pipeline == RenderPipeline::Lines || pipeline == RenderPipeline::Geometry ||
                          pipeline == RenderPipeline::Tessellation || needsMeshShaders(pipeline);
    // Everything after reads or accumulates into these: compute passes,
    // and the graphics pipelines' shaders (the camera block; the geometry
    // and tessellation stages only where those pipelines run: their stage
    // bits need the device's features).
    VkPipelineStageFlags2 readers = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                                    VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    if (pipeline == RenderPipeline::Geometry) readers |= VK_PIPELINE_STAGE_2_GEOMETRY_SHADER_BIT;
    if (pipeline == RenderPipeline::Tessellation)
      readers |= VK_PIPELINE_STAGE_2_TESSELLATION_CONTROL_SHADER_BIT |
                 VK_PIPELINE_STAGE_2_TESSELLATION_EVALUATION_SHADER_BIT;
    // (Only where the mesh stage refuses nothing: the device has the stages.)
    if (needsMeshShaders(pipeline) && frame.context.meshShader().enabled)
      readers |= VK_PIPELINE_STAGE_2_TASK_SHADER_BIT_EXT | VK_PIPELINE_STAGE_2_MESH_SHADER_BIT_EXT;
    const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, readers,
                                 gpu::kStorageReadWrite};
    gpu::PassScope pass(frame.cmd, frame.timer, "clear", after);
    const shader::CameraBlock block =
        makeCameraBlock(frame.camera, frame.settings.line_width_px, frameClipPlanes(frame.settings, frame.camera));
    vkCmdUpdateBuffer(frame.cmd, frame.targets.camera.buffer, 0, sizeof(block), &block);
    if (drawsFiblets(pipeline)) {
      const std::vector<uint32_t> words = sceneTableWords(frame.layout);
      vkCmdUpdateBuffer(frame.cmd, scene_table_.buffer, 0, words.size() * sizeof(uint32_t), words.data());
      frame.scene_table = scene_table_.address;
    }
    if (!graphics) vkCmdFillBuffer(frame.cmd, frame.targets.visibility.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
    // Every word 1.0f: depth 1, which no surface pass and no merge takes
    // (shared/gbuffer.h: SurfaceTexel).
    if (frame.surfaces)
      vkCmdFillBuffer(frame.cmd, frame.targets.surface.buffer, 0, VK_WHOLE_SIZE, std::bit_cast<uint32_t>(1.0f));
  }

 private:
  gpu::Buffer scene_table_;  // shared/scene_table.h
};

}  // namespace

std::unique_ptr<FrameStage> makeSetupStage(const gpu::VulkanContext& context) {
  return std::make_unique<SetupStage>(context);
}

}  // namespace fibscope
