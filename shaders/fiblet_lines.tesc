// Tessellation fiblet pipeline, control stage (paper section 4.5, table 2):
// one patch of one control point per fiblet, one output control point. It
// reads the fiblet's flags and sets the isoline's levels
// (gl_TessLevelOuter = {1, segments}: the decoded segments and the joining
// one, at most 60 < 64, the minimum maxTessellationGenerationLevel); the
// evaluation stage (fiblet_lines.tese) decodes.
//
// Why the decode is not here: the evaluation stage's invocations are
// independent, so each decodes its own vertex (see its header) and nothing
// passes between the stages but the fiblet (patch_fiblet). Two versions
// that decoded here (a 32-invocation patch with the paper's log-step prefix
// across the control-point outputs, barrier() between steps; two
// invocations of 31 points each) were tried while lavapipe's large-draw
// problem (fiblet_graphics_pass.h) still hid every result, and were dropped
// before it was found.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/fiblet_record.glsl"

layout(vertices = 1) out;

layout(push_constant, std430) uniform Push { FibletDrawPush pc; };

layout(location = 0) in uint in_fiblet[];
layout(location = 0) patch out uint patch_fiblet;


void main() {
  const FibletDataset ds = DatasetRef(pc.dataset).ds;
  const uint f = in_fiblet[0];
  patch_fiblet = f;
  uint drawn = 0u;
  if (f < ds.fiblet_count) {
    const uint flags = fibletRecordByte(WordsRef(ds.records), f * ds.record_words, fibletFlagsByte(ds.points_per_fiblet));
    const uint count = fibletCount(flags);
    // The uploader validated the records; never draw garbage.
    if (count >= 1u && count <= ds.points_per_fiblet)
      drawn = count - 1u + ((flags & kFibletFlagEnds) == 0u && f + 1u < ds.fiblet_count ? 1u : 0u);
  }
  // Level 0 discards the patch (nothing to draw: an invalid fiblet, or a
  // lone point ending its fiber, as the compute rasters skip it).
  gl_TessLevelOuter[0] = drawn > 0u ? 1.0 : 0.0;
  gl_TessLevelOuter[1] = float(drawn);
}
