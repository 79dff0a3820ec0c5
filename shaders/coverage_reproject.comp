// The coverage buffer of CullingMode::Coverage (paper section 3.4 and
// appendix C): frame N's covered pixels re-projected into frame N+1 as
// carved hemispheres of radius R_S(z) (the method, the radius and why:
// shared/coverage_push.h). One invocation per pixel of frame N.
//
// Choices:
//   - The sample is the pixel centre at the depth of its visibility key
//     (the nearest fiber drawn there), unprojected in float with N's
//     inverse view-projection (made in double on the CPU).
//   - z in R_S(z) is N's view depth of the sample (its clip w in N), so the
//     radius covers the pixel footprint it was sampled at.
//   - The disc is centred on the sample's projection in the new frame and
//     covers the pixel centres within R_S * focal / w_new of it (w_new: the
//     sample's new view depth), capped at kCoverageMaxSplatPixels.
//   - Its depth is the sample pushed R_S away from the new eye, projected:
//     the back of the hemisphere, the farthest depth of the surface it
//     stands for. Samples behind the new eye (w <= the near distance) or
//     whose back lies past the far plane are dropped: they occlude nothing.
//   - The coverage buffer is the depth pyramid's level 0 (float bits,
//     cleared to 1.0 by the caller); depth_pyramid.comp builds the other
//     levels from it.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shared/workgroup.h"
#include "shared/coverage_push.h"
#include "glsl/render_buffers.glsl"

layout(local_size_x_id = WORKGROUP_SIZE_X_ID, local_size_y_id = WORKGROUP_SIZE_Y_ID) in;  // kPixelGroupSize

layout(push_constant, std430) uniform Push { CoverageReprojectPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 4) buffer CoverageRef { uint depth_bits[]; };

void main() {
  const uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  const uint64_t key = VisibilityRef(pc.previous).keys[visibilityIndex(p.x, p.y, pc.width)];
  if (key == 0xFFFFFFFFFFFFFFFFul) return;  // nothing drawn there in frame N
  const vec2 size = vec2(pc.width, pc.height);
  const vec2 ndc = (vec2(p) + 0.5) / size * 2.0 - 1.0;
  const mat4 inverse_vp = mat4(pc.previous_inverse_view_projection[0], pc.previous_inverse_view_projection[1],
                               pc.previous_inverse_view_projection[2], pc.previous_inverse_view_projection[3]);
  const vec4 h = inverse_vp * vec4(ndc, visibilityDepth(key), 1.0);
  if (!(h.w > 0.0)) return;
  const vec3 world = h.xyz / h.w;
  // N's clip w of the sample is 1 / h.w (clip = (ndc, 1) * w and the
  // inverse maps clip to homogeneous world with w_world = 1).
  const float radius = coverageSplatRadius(1.0 / h.w, pc.previous_focal_px, pc.splat_pixels);

  const CameraBlock cam = CameraRef(pc.camera).camera;
  const vec4 centre = cameraTransformPoint(cam.view_projection, world);
  if (!(centre.w > cam.depth_range.x)) return;
  const vec3 away = world - cam.eye.xyz;
  const float distance = length(away);
  if (!(distance > 0.0)) return;
  const vec4 back = cameraTransformPoint(cam.view_projection, world + away * (radius / distance));
  if (!(back.w > 0.0)) return;
  const float depth = back.z / back.w;
  if (!(depth >= 0.0) || !(depth < 1.0)) return;

  const vec2 c = (centre.xy / centre.w + 1.0) * 0.5 * size;  // window coordinates
  const float r = min(radius * pc.focal_px / centre.w, kCoverageMaxSplatPixels);
  // Pixel centres px + 0.5 within r of c, clamped to the frame in float.
  const vec2 first = max(ceil(c - r - 0.5), vec2(0.0));
  const vec2 last = min(floor(c + r - 0.5), size - 1.0);
  if (first.x > last.x || first.y > last.y) return;
  CoverageRef coverage = CoverageRef(pc.coverage);
  const uint bits = floatBitsToUint(depth);
  for (float y = first.y; y <= last.y; y += 1.0)
    for (float x = first.x; x <= last.x; x += 1.0) {
      const vec2 d = vec2(x, y) + 0.5 - c;
      if (dot(d, d) <= r * r) atomicMin(coverage.depth_bits[uint(y) * pc.width + uint(x)], bits);
    }
}
