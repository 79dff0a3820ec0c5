// Surfaces: the spline tubes ray-cast in the fragment shader (Salm, seed
// section 3.2 and figure 17; issue 15 item 3), the graphics twin of the
// compute caster (tubeRaycastStage in gpu_tubes.h), giving the same texels.
//
// Design (shared/tube_raster.h): one instanced draw of the tight oriented
// box of every quadratic sub-segment (tube_box.vert; instances =
// sub-segments, no culling), whose fragments ray-cast their sub-segment and
// keep the nearest hit per pixel by a 64-bit atomicMin into the stage's own
// visibility buffer (tube_box.frag), then one compute resolve that writes
// the winner's texel with the compute caster's code (tube_raster_resolve.comp,
// glsl/tube_texel.glsl). No colour or depth attachments: the G-buffer's
// surface target is a storage buffer of 8-word texels, which a fragment
// shader cannot write nearer-wins by itself, and a depth attachment would
// only order the fragments, not make the texel writes of one pixel atomic.
// The key's order (depth, then item) is the compute caster's, and the
// resolve tests "strictly nearer than the surface target" as it does.
//
// Needs the device's fragmentStoresAndAtomics (lavapipe has it) and a
// graphics queue; check() throws Error naming the feature where it lacks.
#pragma once

#include "render/gpu/frame_stage.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {

// "tube boxes" and "tube resolve" into the surface target; runs in frames
// where `tubes` is not null and has segments. `tubes` is read at every
// frame and must outlive the renderer.
FrameStageFactory tubeRasterRaycastStage(const GpuTubes* tubes);

}  // namespace fibscope
