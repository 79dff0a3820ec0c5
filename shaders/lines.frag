// Lines baseline: writes the G-buffer texel's four words (shared/gbuffer.h)
// into an R32G32B32A32_UINT attachment; the depth attachment (LESS) keeps
// the nearest fragment, and the pass copies the attachment into the
// G-buffer storage buffer.
#version 460

layout(location = 0) flat in uint in_fiber;
layout(location = 1) flat in uint in_segment;
layout(location = 2) flat in uint in_tangent;

layout(location = 0) out uvec4 texel;

void main() { texel = uvec4(floatBitsToUint(gl_FragCoord.z), in_fiber, in_segment, in_tangent); }
