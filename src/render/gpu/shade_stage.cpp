// Shading: colour mode x lighting x occlusion -> RGBA8 (shade.comp) in the
// covered tiles. The parameters go in a ShadeBlock written with the frame's
// commands; the colour mode, the lighting and whether the frame has
// surfaces select one of the shader's specialised pipelines (made when a
// frame first needs it, or by prepare), so no pixel runs the others' code.
#include <array>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/pass_scope.h"
#include "render/colormap.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/shading_stages.h"
#include "shared/render_config.h"
#include "shared/shade_push.h"

namespace fibscope {
namespace {

constexpr uint32_t kColorModes = 5, kLightings = 3;
// What the frame's surfaces ask of the shade pass.
constexpr uint32_t kNoSurfaces = 0, kOpaqueSurfaces = 1, kTranslucentSlices = 2, kSurfaceKinds = 3;

uint32_t shaderColorMode(ColorMode mode) {
  switch (mode) {
    case ColorMode::Solid: return shader::kShadeColorSolid;
    case ColorMode::Orientation: return shader::kShadeColorOrientation;
    case ColorMode::PerFiber: return shader::kShadeColorPerFiber;
    case ColorMode::Scalar: return shader::kShadeColorScalar;
    case ColorMode::Normal: return shader::kShadeColorNormal;
  }
  return shader::kShadeColorOrientation;
}

uint32_t shaderLighting(Lighting lighting) {
  switch (lighting) {
    case Lighting::None: return shader::kShadeLightingNone;
    case Lighting::IlluminatedLines: return shader::kShadeLightingIlluminated;
    case Lighting::Pbr: return shader::kShadeLightingPbr;
  }
  return shader::kShadeLightingNone;
}

class ShadeStage final : public FrameStage {
 public:
  explicit ShadeStage(const gpu::VulkanContext& context)
      : block_(gpu::createBuffer(context, sizeof(shader::ShadeBlock), gpu::MemoryUse::DeviceLocal)),
        colormaps_(allColormapTables()) {}
  void destroy(const gpu::VulkanContext& context) override {
    for (gpu::ComputePipeline& p : variants_) gpu::destroyComputePipeline(context, p);
    gpu::destroyBuffer(context, block_);
  }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext&) const override { return true; }
  void prepare(const gpu::VulkanContext& context, const RenderSettings& settings) override {
    variant(context, shaderColorMode(settings.color), shaderLighting(settings.lighting), kNoSurfaces);
  }

  void record(FrameContext& frame) override {
    const RenderSettings& s = frame.settings;
    const GpuFrameTargets& t = frame.targets;
    shader::ShadeBlock block{};
    block.fiber_scalars = frame.scene.fiber_scalars;
    block.selection_bits = frame.scene.selection_bits;
    block.fiber_count = frame.fiber_count;
    block.solid = packRgba8(s.solid_color);
    block.background = packRgba8(s.background);
    block.ambient = s.light_ambient;
    block.diffuse = s.light_diffuse;
    block.specular = s.light_specular;
    block.shininess = s.light_shininess;
    block.scalar_min = s.scalar_min;
    block.scalar_max = s.scalar_max;
    block.highlight = packRgba8(s.highlight_color);
    block.dim_unselected = s.dim_unselected;
    block.roughness = s.pbr_roughness;
    block.metalness = s.pbr_metalness;
    block.light_intensity = s.pbr_intensity;
    const size_t table = size_t(s.colormap) * kColormapEntries;
    std::copy(colormaps_.begin() + table, colormaps_.begin() + table + kColormapEntries, block.colormap);
    // The previous frame's reads of the block before the update, the
    // update before this frame's.
    gpu::recordBarrier(frame.cmd, {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, 0});
    vkCmdUpdateBuffer(frame.cmd, block_.buffer, 0, sizeof(block), &block);
    gpu::recordBarrier(frame.cmd, gpu::kTransferToCompute);

    // Without scalars the scalar mode draws orientation (render_settings.h).
    uint32_t mode = shaderColorMode(s.color);
    if (mode == shader::kShadeColorScalar && frame.scene.fiber_scalars == 0) mode = shader::kShadeColorOrientation;
    // Translucent slices: the merge leaves the pixels behind them, shade
    // blends the slice over them (shared/surface_push.h).
    const bool translucent = frame.surfaces && frame.scene.anatomy && s.anatomy_opacity < 1.0f;
    const uint32_t surfaces = !frame.surfaces ? kNoSurfaces : (translucent ? kTranslucentSlices : kOpaqueSurfaces);
    const gpu::ComputePipeline& pipeline = variant(frame.context, mode, shaderLighting(s.lighting), surfaces);

    gpu::PassScope pass(frame.cmd, frame.timer, "shade", gpu::kComputeToCompute);
    shader::ShadePush push{};
    push.camera = t.camera.address;
    push.gbuffer = t.gbuffer.address;
    push.surface = frame.surfaces ? t.surface.address : 0;
    push.ao = ssaoRuns(s) || frame.df_ao ? t.ao.address : 0;
    push.shadow = frame.df_shadow ? t.ao_blur.address : 0;
    push.color = (shadeTarget(s) == ShadeTarget::Shaded ? t.shaded : t.color).address;
    push.tiles = t.tile_list.address;
    push.block = block_.address;
    push.width = t.width;
    push.height = t.height;
    gpu::recordDispatchIndirect(frame.cmd, pipeline, push, t.tile_list.buffer);
  }

 private:
  const gpu::ComputePipeline& variant(const gpu::VulkanContext& context, uint32_t mode, uint32_t lighting,
                                      uint32_t surfaces) {
    gpu::ComputePipeline& p = variants_[(mode * kLightings + lighting) * kSurfaceKinds + surfaces];
    if (p.pipeline == VK_NULL_HANDLE) {
      std::array<uint32_t, 4> spec{};
      spec[shader::kShadeSpecColorMode] = mode;
      spec[shader::kShadeSpecLighting] = lighting;
      spec[shader::kShadeSpecSurfaces] = surfaces != kNoSurfaces ? 1u : 0u;
      spec[shader::kShadeSpecTranslucentSlices] = surfaces == kTranslucentSlices ? 1u : 0u;
      p = gpu::createComputePipeline(context, "shade.comp", sizeof(shader::ShadePush),
                                     gpu::WorkgroupSize{shader::kPixelGroupSize, shader::kPixelGroupSize}, spec);
    }
    return p;
  }

  gpu::Buffer block_;                                         // shader::ShadeBlock
  std::vector<uint32_t> colormaps_;                           // every colormap's table (colormap.h)
  std::array<gpu::ComputePipeline, kColorModes * kLightings * kSurfaceKinds> variants_{};  // (mode, lighting, surfaces)
};

}  // namespace

std::unique_ptr<FrameStage> makeShadeStage(const gpu::VulkanContext& context) {
  return std::make_unique<ShadeStage>(context);
}

}  // namespace fibscope
