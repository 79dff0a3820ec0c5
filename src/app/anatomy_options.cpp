#include "app/anatomy_options.h"

#include "render/anatomy_slices.h"

namespace fibscope {

std::optional<NiftiVolume> readAnatomyOption(const RenderCliOptions& o) {
  if (o.anatomy.empty()) return std::nullopt;
  return loadAnatomyVolume(o.anatomy);
}

void applyAnatomy(const gpu::VulkanContext& context, const NiftiVolume& volume, const RenderCliOptions& o,
                  std::span<RenderSettings* const> settings, GpuAnatomy& anatomy, GpuScene& scene) {
  anatomy = GpuAnatomy::upload(context, volume);
  scene.anatomy = &anatomy;
  for (RenderSettings* s : settings)
    fitAnatomySettings(*s, anatomy.grid(), anatomy.robustRange(), [&](std::string_view name) { return o.gave(name); });
}

Camera withAnatomyInView(const Camera& camera, const GpuAnatomy& anatomy) {
  if (anatomy.empty()) return camera;
  const std::array<Vec3d, 8> corners = volumeCorners(anatomy.grid());
  return enclosingDepthRange(camera, corners);
}

}  // namespace fibscope
