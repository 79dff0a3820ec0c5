// The camera block shared by the C++ renderer and the shaders (a storage
// block read through a buffer reference, std430: vec4s and arrays of vec4,
// then the mesh cuts' addresses).
//
// Conventions (Vulkan; src/render/camera.h builds the matrices, the CPU
// reference rasteriser src/render/reference_raster.h follows them exactly):
//   - world space is RAS+ millimetres (DESIGN.md section 4);
//   - the view is right-handed and looks down its -z axis: x_view to the
//     right of the image, y_view up in the image;
//   - clip depth lies in [0, 1]: the near plane maps to 0, the far plane to
//     1 (z_ndc = z_clip / w_clip; w_clip = -z_view > 0 in front of the eye);
//   - the framebuffer's y axis points DOWN: y_ndc = -1 is the top row
//     (the projection negates y_view, no negative viewport height needed);
//   - window coordinates: x_w = (x_ndc + 1) * width / 2,
//                         y_w = (y_ndc + 1) * height / 2;
//     pixel (px, py) covers [px, px + 1) x [py, py + 1), centre
//     (px + 0.5, py + 0.5);
//   - matrices are column-major, stored as four vec4 COLUMNS (glsl_cpp.h has
//     no mat4 for C++): m[c] is column c, so clip = m[0] * x + m[1] * y +
//     m[2] * z + m[3] * 1; GLSL code may build mat4(m[0], m[1], m[2], m[3])
//     but cameraToClip below spells the product out so that CPU and GPU
//     evaluate it in the same order.
#ifndef FIBSCOPE_SHADERS_SHARED_CAMERA_H
#define FIBSCOPE_SHADERS_SHARED_CAMERA_H

#include "shared/glsl_cpp.h"
#include "shared/cut_mesh.h"

#ifdef __cplusplus
#include <cstddef>
#endif

SHADER_NAMESPACE_BEGIN

#ifdef __cplusplus
#define CAMERA_CONST inline constexpr
#else
#define CAMERA_CONST const
#endif

// Cuts (DESIGN.md section 2): up to kMaxClipPlanes planes of the user's
// and the slab's two, each keeping the half-space n.p + d >= 0.
CAMERA_CONST uint kMaxClipPlanes = 6u;
CAMERA_CONST uint kMaxFrameClipPlanes = 8u;

struct CameraBlock {
  vec4 view_projection[4];  // world mm -> clip, columns
  vec4 view[4];             // world mm -> view (eye at origin, looking down -z), columns
  vec4 eye;                 // xyz: eye position in world mm; w = 1
  vec4 viewport;            // x: width px, y: height px, z: line width px, w: 0
  vec4 depth_range;         // x: near mm, y: far mm (view-space distances); z, w: 0
  // The frame's clip planes: in world space (n, d) for tests of world
  // points (the cull, the lines' clip distances), and the same planes in
  // clip space (transpose(inverse(view_projection)) (n, d), made in double)
  // for the rasters, which clip segments between clip-space ends: clipping
  // there is exact clipping in world space, the map being affine.
  vec4 clip_world[kMaxFrameClipPlanes];
  vec4 clip_space[kMaxFrameClipPlanes];
  vec4 cuts;  // x: clip planes in use (a count, 0 .. kMaxFrameClipPlanes); y, z, w: 0
  // The mesh cuts' depth buffers and tiles (shared/cut_mesh.h); mesh_count
  // 0: none. Written by the mesh-cut stage after the setup stage.
  CutMeshFrame mesh_cuts;
};

// Column-major 4x4 times (p, 1), summed column by column in a fixed order.
SHADER_FN vec4 cameraTransformPoint(vec4 m[4], vec3 p) {
  SHADER_PRECISE float x = ((m[0].x * p.x + m[1].x * p.y) + m[2].x * p.z) + m[3].x;
  SHADER_PRECISE float y = ((m[0].y * p.x + m[1].y * p.y) + m[2].y * p.z) + m[3].y;
  SHADER_PRECISE float z = ((m[0].z * p.x + m[1].z * p.y) + m[2].z * p.z) + m[3].z;
  SHADER_PRECISE float w = ((m[0].w * p.x + m[1].w * p.y) + m[2].w * p.z) + m[3].w;
  return vec4(x, y, z, w);
}

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::CameraBlock) == 480, "camera block: 28 vec4 and the mesh cuts, no padding");
static_assert(offsetof(fibscope::shader::CameraBlock, mesh_cuts) == 448, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_CAMERA_H
