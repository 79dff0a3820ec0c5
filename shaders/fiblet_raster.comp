// Decode + raster (DESIGN.md section 6, step 2; fiblets paper 3.3.2).
// LANES invocations decode one fiblet (a specialization constant: 8 where
// the subgroup scan of fiblet_raster_subgroup.comp fits, else 64, 32 or 16
// from the device's subgroup size); a workgroup holds GROUP_FIBLETS fiblets
// (GPUs: one subgroup's worth with the subgroup scan, else one fiblet per
// workgroup as in the paper; 64 / LANES on CPU devices such as lavapipe,
// where every workgroup costs about a microsecond of dispatch).
// The fiblet's up to 64 point transforms are split into LANES runs of
// 64 / LANES consecutive transforms:
//   1. each invocation composes its run sequentially, keeping the run's
//      local prefix translations (at most 8 for LANES = 8);
//   2. a log-step inclusive scan of the runs' products in shared memory
//      (Hillis-Steele: log2(LANES) steps, shared memory + barriers, so it
//      works for any subgroup size);
//   3. each invocation maps its local points through the exclusive prefix
//      (a rotation and a translation each) and rasterises the segment that
//      starts at each point (glsl/raster_segment.glsl: the CPU reference's
//      pixel rule).
// With LANES = 64 this is the paper's one-transform-per-thread scan; fewer
// lanes do less work (about one composition per point instead of
// log2(64) = 6) and fewer barriers: a CPU rasteriser needs that, and a GPU
// gains too (H100: 8 lanes 20 % faster than 32).
// The invocation that owns the last point also draws the segment that
// joins the next fiblet of the same fiber (its first point).
// Payload: fiblet << 6 | index of the segment's first point in the fiblet.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#define FIBLET_SUBGROUP_SCAN 0
#include "glsl/fiblet_raster_body.glsl"
