// `--anatomy FILE.nii[.gz]` of render and bench (app/render_options.h):
// the volume read before any other work (a bad file is one line naming it),
// then on the device with the slices at its centre and its robust display
// range, unless the command line gave them (render/anatomy_slices.h).
#pragma once

#include <optional>
#include <span>

#include "app/render_options.h"
#include "io/nifti_volume.h"
#include "render/camera.h"
#include "render/gpu/anatomy.h"
#include "render/gpu/scene.h"
#include "render/render_settings.h"

namespace fibscope {

// The volume --anatomy names (loadAnatomyVolume), or none without the
// option. Throws Error "PATH: ..." (one line).
std::optional<NiftiVolume> readAnatomyOption(const RenderCliOptions& options);

// Uploads `volume` into `anatomy` (kept by the caller while the scene is
// drawn), points scene.anatomy at it and fits each of `settings` to it
// (fitAnatomySettings: what the command line gave stays). Throws Error
// "PATH: ..." (GpuAnatomy::upload).
void applyAnatomy(const gpu::VulkanContext& context, const NiftiVolume& volume, const RenderCliOptions& options,
                  std::span<RenderSettings* const> settings, GpuAnatomy& anatomy, GpuScene& scene);

// The camera with its depth range widened to the whole volume (when there
// is one), so that no slice is cut by the near or far plane.
Camera withAnatomyInView(const Camera& camera, const GpuAnatomy& anatomy);

}  // namespace fibscope
