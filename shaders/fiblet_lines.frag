// The geometry and tessellation fiblet pipelines' fragment shader: the
// lines baseline's texel rule (glsl/line_texel.glsl) on the flat values of
// the segment's provoking vertex.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/render_push.h"
#include "glsl/line_texel.glsl"

layout(push_constant, std430) uniform Push { FibletDrawPush pc; };

layout(location = 0) flat in uint in_fiber;
layout(location = 1) flat in uint in_segment;
layout(location = 2) flat in uint in_tangent;

layout(location = 0) out uvec4 texel;

void main() { texel = lineTexel(pc.camera, in_fiber, in_segment, in_tangent); }
