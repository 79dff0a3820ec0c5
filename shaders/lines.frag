// Lines baseline: writes the G-buffer texel's four words (shared/gbuffer.h)
// into an R32G32B32A32_UINT attachment; the depth attachment (LESS) keeps
// the nearest fragment, and the pass copies the attachment into the
// G-buffer storage buffer. The texel and the mesh cuts' discard:
// glsl/line_texel.glsl, shared with the fiblet graphics pipelines.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "glsl/raw_tractogram.glsl"
#include "glsl/line_texel.glsl"

layout(push_constant, std430) uniform Push { LinesPush pc; };

layout(location = 0) flat in uint in_fiber;
layout(location = 1) flat in uint in_segment;
layout(location = 2) flat in uint in_tangent;

layout(location = 0) out uvec4 texel;

void main() { texel = lineTexel(pc.camera, in_fiber, in_segment, in_tangent); }
