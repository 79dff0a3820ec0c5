// Helpers of the shading passes (ssao.comp, ssao_blur.comp, shade.comp):
// view depth from the G-buffer's clip depth, the camera's axes and the
// per-pixel view ray, and the per-fiber colour. The camera is the
// perspective one of src/render/camera.h (symmetric frustum, Vulkan depth).
#ifndef FIBSCOPE_GLSL_SHADE_COMMON_GLSL
#define FIBSCOPE_GLSL_SHADE_COMMON_GLSL

#include "glsl/render_buffers.glsl"

// The pixel of this invocation in a pass run one workgroup
// (kPixelGroupSize x kPixelGroupSize) per listed tile (tile_classify.comp):
// the flattened workgroup index picks the tile, the local id the pixel in
// it. False past the list's end (the 2D grid may overshoot) and outside the
// frame. Compute shaders only: a graphics stage (tube_box.frag, for
// pixelToEye) defines SHADE_COMMON_NO_TILES before the include.
#ifndef SHADE_COMMON_NO_TILES
bool tilePixel(uint64_t tiles, uint width, uint height, out uvec2 p) {
  p = uvec2(0u);
  TileListRef list = TileListRef(tiles);
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (group >= list.header.count) return false;
  const uint tile = list.tiles[group], tiles_x = pixelGroups(width);
  p = uvec2(tile % tiles_x, tile / tiles_x) * kPixelGroupSize + gl_LocalInvocationID.xy;
  return p.x < width && p.y < height;
}
#endif

// Distance along the view axis (mm) of clip depth d = z/w in [0, 1]:
// camera.cpp's projection gives d = f (z - n) / ((f - n) z) for z the
// distance, so z = n f / (f - d (f - n)).
float viewDistance(CameraBlock cam, float d) {
  const float n = cam.depth_range.x, f = cam.depth_range.y;
  return n * f / (f - d * (f - n));
}

// The view's axes in world space: the rows of the view matrix's rotation
// (view[c] is column c, so row r is (view[0][r], view[1][r], view[2][r])).
vec3 cameraRight(CameraBlock cam) { return vec3(cam.view[0].x, cam.view[1].x, cam.view[2].x); }
vec3 cameraUp(CameraBlock cam) { return vec3(cam.view[0].y, cam.view[1].y, cam.view[2].y); }
vec3 cameraBack(CameraBlock cam) { return vec3(cam.view[0].z, cam.view[1].z, cam.view[2].z); }

// Unit vector from the surface seen at pixel (px, py) towards the eye. For
// a perspective camera it depends on the pixel only, not on the depth: the
// eye ray through the pixel centre in view space is (x_ndc / P00,
// y_ndc / P11, -1), and P00, P11 are recovered from view_projection = P V,
// whose first two rows are P00 and P11 times the view's right and up rows.
vec3 pixelToEye(CameraBlock cam, uvec2 p) {
  const vec3 right = cameraRight(cam), up = cameraUp(cam);
  const float p00 = dot(vec3(cam.view_projection[0].x, cam.view_projection[1].x, cam.view_projection[2].x), right);
  const float p11 = dot(vec3(cam.view_projection[0].y, cam.view_projection[1].y, cam.view_projection[2].y), up);
  const vec2 ndc = (vec2(p) + 0.5) / cam.viewport.xy * 2.0 - 1.0;
  const vec3 ray = (ndc.x / p00) * right + (ndc.y / p11) * up - cameraBack(cam);
  return -normalize(ray);
}

// A well-mixed 32-bit hash (lowbias32, Chris Wellons' integer hash search).
uint shadeHash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

vec3 hsvToRgb(float h, float s, float v) {
  const vec3 k = clamp(abs(fract(h + vec3(0.0, 2.0 / 3.0, 1.0 / 3.0)) * 6.0 - 3.0) - 1.0, 0.0, 1.0);
  return v * mix(vec3(1.0), k, s);
}

// A stable colour per fiber index: hue from 16 bits of the hash, saturation
// in [0.45, 0.85] and value in [0.75, 1] from 8 bits each, so no fiber is
// grey or dark.
vec3 fiberColor(uint fiber) {
  const uint h = shadeHash(fiber);
  const float hue = float(h & 0xFFFFu) / 65536.0;
  const float sat = 0.45 + 0.4 * float((h >> 16) & 0xFFu) / 255.0;
  const float val = 0.75 + 0.25 * float(h >> 24) / 255.0;
  return hsvToRgb(hue, sat, val);
}

#endif
