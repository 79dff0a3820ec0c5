// The stages of a frame (frame_stage.h), one factory each, and the
// standard list FrameRenderer runs. Each stage lives in its own file
// (gpu_<name>_stage.cpp) with the passes it records.
#pragma once

#include "render/gpu/frame_stage.h"

namespace fibscope {

// "clear": the camera block and the scene table written, the visibility
// buffer cleared (not for lines, which have their own depth attachment),
// the surface target cleared in a frame with surfaces.
std::unique_ptr<FrameStage> makeSetupStage(const gpu::VulkanContext& context);
// Geometry, one per frame by settings.pipeline:
// "fiblet bounds", "cull"/"raster" (or the two-phase passes), "resolve":
// the compute pipeline over the scene's datasets (cull_passes.h,
// fiblet_passes.h).
// Mesh cuts: each cut mesh's front and back depths (shared/cut_mesh.h).
std::unique_ptr<FrameStage> makeCutMeshStage(const gpu::VulkanContext& context);
std::unique_ptr<FrameStage> makeFibletStage(const gpu::VulkanContext& context);
// "raster", "resolve": the raw-compute baseline (raw_passes.h).
std::unique_ptr<FrameStage> makeRawComputeStage(const gpu::VulkanContext& context);
// "lines": the graphics-pipeline baseline (lines_pass.h; its pipeline
// made at the first lines frame: compute-only devices never need it).
std::unique_ptr<FrameStage> makeLinesStage(const gpu::VulkanContext& context);
// "cull" (frustum or the fiber filter), "geometry" / "tessellation": the
// paper's comparison pipelines over the scene's fiblets
// (fiblet_graphics_pass.h; pipelines made at their first frame).
std::unique_ptr<FrameStage> makeGeometryStage(const gpu::VulkanContext& context);
std::unique_ptr<FrameStage> makeTessellationStage(const gpu::VulkanContext& context);
// "mesh" / "mesh-serial" (or "... 1", "depth pyramid", "... 2"): the task
// shader's cull and the mesh shader's decode (fiblet_mesh_pass.h;
// VK_EXT_mesh_shader only, refused in one line without it).
std::unique_ptr<FrameStage> makeMeshStage(const gpu::VulkanContext& context);
std::unique_ptr<FrameStage> makeMeshSerialStage(const gpu::VulkanContext& context);
// Surfaces: "spheres", GpuScene::spheres ray-cast (sphere_surface.comp).
std::unique_ptr<FrameStage> makeSphereStage(const gpu::VulkanContext& context);
// Surfaces: "slices", GpuScene::anatomy's slices ray-cast (anatomy_slices.comp).
std::unique_ptr<FrameStage> makeAnatomyStage(const gpu::VulkanContext& context);
// "surface merge": the surface target into the G-buffer (surface_merge.comp).
std::unique_ptr<FrameStage> makeSurfaceMergeStage(const gpu::VulkanContext& context);
// Shading (shading_stages.h).
std::unique_ptr<FrameStage> makeTilesStage(const gpu::VulkanContext& context);
std::unique_ptr<FrameStage> makeSsaoStage(const gpu::VulkanContext& context);
std::unique_ptr<FrameStage> makeShadeStage(const gpu::VulkanContext& context);
// "post": post effects after shading (and AO), before FXAA (post_stage.cpp).
std::unique_ptr<FrameStage> makePostStage(const gpu::VulkanContext& context);
std::unique_ptr<FrameStage> makeFxaaStage(const gpu::VulkanContext& context);
// "orientation": the orientation labels and axis triad over the final
// image (orientation_overlay.comp), after FXAA.
std::unique_ptr<FrameStage> makeOrientationStage(const gpu::VulkanContext& context);

// tiles, ssao, shade, post, fxaa: the G-buffer (and surface target) -> RGBA8.
FrameStageList shadingStages();
// Everything a frame of any pipeline needs, in order: setup, the seven
// geometry stages, the surface stages, merge, shading, the orientation
// overlay.
FrameStageList standardFrameStages();

}  // namespace fibscope
