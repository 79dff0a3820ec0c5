// Surfaces: the spline tubes by adaptive tessellation (Salm, seed section
// 3.1; issue 15 item 2), beside the two ray casters (gpu_tubes.h,
// tube_raster_stage.h) and writing the same surface texels.
//
// Design (shared/tube_tess.h): every Hermite segment is a base mesh of
// tube_rings x tube_vertices quad patches (RenderSettings, 16 x 8 by
// default) and two rows of hemispherical cap patches, in one draw of
// one-vertex patches (split in draws of 64 on CPU devices:
// gpu/tessellation_draws.h). The control stage culls back patches and the
// caps between joined segments and refines by the edge-length and
// silhouette criteria; the evaluation stage places the vertices on the
// Hermite tube with the nodes' rotation-minimising frames interpolated.
// As the fragment-shader ray caster, no attachments: the surface target
// is a storage buffer of 8-word texels, so the nearest fragment per pixel
// is found by a 64-bit atomicMin (draw "tube tess"), and the same geometry
// drawn again lets the winner write its texel where it is strictly nearer
// than the surface target ("tube tess texels").
//
// tube_msaa (1, 4, 8): supersampled coverage, not blended MSAA (the
// surface target holds one texel per pixel; shared/tube_tess.h says what
// is done and why).
//
// Needs tessellationShader, fragmentStoresAndAtomics, a graphics queue and
// tube_msaa among framebufferNoAttachmentsSampleCounts;
// check() throws Error naming what the device lacks.
#pragma once

#include "render/gpu/frame_stage.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {

struct TubeTessOptions {
  // Back-patch and frustum culling in the control stage (off: every patch
  // tessellated, for the tests that culling changes no texel).
  bool back_patch_culling = true;
  bool frustum_culling = true;
};

// "tube tess" and "tube tess texels" into the surface target; runs in
// frames where `tubes` is not null and has segments. `tubes` is read at
// every frame and must outlive the renderer.
FrameStageFactory tubeTessellationStage(const GpuTubes* tubes);
FrameStageFactory tubeTessellationStage(const GpuTubes* tubes, TubeTessOptions options);

}  // namespace fibscope
