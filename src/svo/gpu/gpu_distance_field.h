// The tubes' dense distance field on the device (issue 16 item 4;
// shaders/shared/distance_field.h): built once per tube model by the
// octree's voxelisation pass (svo_voxelize.comp, wide band, one slab: the
// field is at most 64 MB at the automatic voxel) and df_finalize.comp, and
// the frame stage of the distance-field passes "df ao" (df_ao.comp, in
// place of SSAO when RenderSettings::ao_method is Df) and "df shadow"
// (df_shadow.comp, with RenderSettings::df_shadows).
#pragma once

#include <vector>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/frame_stage.h"
#include "svo/distance_field.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {

struct GpuDistanceField {
  gpu::Buffer values;  // float per voxel (shared/distance_field.h layout)
  DistanceFieldGrid grid;
  double build_s = 0;  // wall time of the build (host clock)
};

// The field of `model`'s capsules (uploaded as `tubes`) on `grid`
// (chooseDistanceFieldGrid). Throws Error when memory runs out.
GpuDistanceField buildDistanceFieldGpu(const gpu::VulkanContext& context, const GpuTubes& tubes,
                                       const DistanceFieldGrid& grid);
void destroyDistanceField(const gpu::VulkanContext& context, GpuDistanceField& field);
std::vector<float> downloadDistanceField(const gpu::VulkanContext& context, const GpuDistanceField& field);

// Whether a frame with these settings runs the distance-field passes.
bool distanceFieldAoRuns(const RenderSettings& settings);
bool distanceFieldShadowsRun(const RenderSettings& settings);

// Shading: "df ao" and "df shadow" over `field` (read every frame; must
// outlive the renderer; null or empty: the stage does not run).
FrameStageFactory distanceFieldStage(const GpuDistanceField* field);
// `stages` with the distance-field stage inserted before the shade stage.
FrameStageList withDistanceFieldStage(FrameStageList stages, const GpuDistanceField* field);

}  // namespace fibscope
