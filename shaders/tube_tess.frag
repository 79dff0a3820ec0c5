// Spline tubes by adaptive tessellation, fragment stage (shared/tube_tess.h):
// draw 1 keeps the nearest fragment per pixel by a 64-bit atomicMin of
// (clip depth bits << 32 | patch index); draw 2 (the same geometry, the
// same pipeline) lets the fragment holding the pixel's key write the
// surface texel as the ray casters do (glsl/tube_texel.glsl's fields),
// when strictly nearer than the surface target's depth. A pixel gets one
// fragment per covering triangle, and a patch's triangles do not overlap,
// so one fragment at most matches its key. No attachments.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require

#include "shared/gbuffer.h"
#include "shared/tube_tess.h"
#include "glsl/tangent.glsl"
#include "glsl/cut_mesh.glsl"

layout(push_constant, std430) uniform Push { TubeTessPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 8) buffer KeysRef { uint64_t keys[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer SurfaceRef { SurfaceTexel texels[]; };

layout(location = 0) in vec3 in_normal;
layout(location = 1) in vec3 in_tangent;
layout(location = 2) in float in_position;
layout(location = 3) in vec4 in_color;
layout(location = 4) flat in uint in_patch;
layout(location = 5) flat in uint in_fiber;

void main() {
  const uvec2 p = uvec2(gl_FragCoord.xy);
  const uint index = p.y * pc.width + p.x;
  const float depth = gl_FragCoord.z;
  if (!(depth >= 0.0 && depth <= 1.0)) return;
  // Mesh cuts per pixel (the clip planes clipped the triangles already:
  // tube_tess.tese), as surface_cuts.glsl.
  const CameraBlock cam = CameraRef(pc.camera).camera;
  if (cam.mesh_cuts.mesh_count != 0u &&
      !cutMeshesKeep(cam.mesh_cuts, uint(cam.viewport.x) * uint(cam.viewport.y), index, depth))
    return;
  const uint64_t key = (uint64_t(floatBitsToUint(depth)) << 32) | uint64_t(in_patch);
  KeysRef keys = KeysRef(pc.visibility);
  if (pc.samples <= 1u) {
    if (pc.mode == kTubeTessModeKeys) {
      atomicMin(keys.keys[index], key);
      return;
    }
    if (keys.keys[index] != key) return;
  } else {
    // Supersampled coverage (shared/tube_tess.h): a key per sample.
    const uint base = index * pc.samples, mask = uint(gl_SampleMaskIn[0]);
    if (pc.mode == kTubeTessModeKeys) {
      for (uint k = 0u; k < pc.samples; ++k)
        if (((mask >> k) & 1u) != 0u) atomicMin(keys.keys[base + k], key);
      return;
    }
    // The pixel is the tubes' when half its samples are; its texel is that
    // of the fragment nearest at the most samples (ties: the nearer).
    uint64_t sample_keys[8];
    uint covered = 0u;
    for (uint k = 0u; k < pc.samples; ++k) {
      sample_keys[k] = keys.keys[base + k];
      covered += sample_keys[k] != 0xFFFFFFFFFFFFFFFFul ? 1u : 0u;
    }
    if (2u * covered < pc.samples) return;
    uint64_t winner = 0xFFFFFFFFFFFFFFFFul;
    uint most = 0u;
    for (uint k = 0u; k < pc.samples; ++k) {
      if (sample_keys[k] == 0xFFFFFFFFFFFFFFFFul) continue;
      uint n = 0u;
      for (uint j = 0u; j < pc.samples; ++j) n += sample_keys[j] == sample_keys[k] ? 1u : 0u;
      if (n > most || (n == most && sample_keys[k] < winner)) {
        most = n;
        winner = sample_keys[k];
      }
    }
    if (winner != key) return;
  }
  SurfaceRef surface = SurfaceRef(pc.surface);
  if (!(depth < surface.texels[index].depth)) return;
  SurfaceTexel texel;
  texel.depth = depth;
  texel.fiber = in_fiber;
  texel.normal = packSegmentTangent(in_normal);
  texel.tangent = dot(in_tangent, in_tangent) > 0.0 ? packSegmentTangent(in_tangent) : texel.normal;
  texel.position = in_position;
  texel.color = in_color.a > 0.5 ? packUnorm4x8(vec4(clamp(in_color.rgb, 0.0, 1.0), 1.0)) : 0u;
  texel.source = kSurfaceSourceTube;
  texel.pad0 = 0u;
  surface.texels[index] = texel;
}
