// The surface passes (shared/gbuffer.h: the surface target) and the merge
// of the surface target into the G-buffer. Buffers are device addresses;
// the uint64_t members first, so std430 and C++ agree.
//
//   sphere_surface.comp  analytic spheres, ray-cast per pixel
//   anatomy_slices.comp  anatomical slices (shared/anatomy.h)
//   surface_merge.comp   surface pixels nearer than the lines -> G-buffer
#ifndef FIBSCOPE_SHADERS_SHARED_SURFACE_PUSH_H
#define FIBSCOPE_SHADERS_SHARED_SURFACE_PUSH_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#define SURFACE_CONST inline constexpr
#else
#define SURFACE_CONST const
#endif

SHADER_NAMESPACE_BEGIN

// Spheres one frame draws at most (uploaded with the frame's commands,
// 32 bytes each: within vkCmdUpdateBuffer's 64 KiB).
SURFACE_CONST uint kMaxSurfaceSpheres = 1024u;

// A sphere in world mm: its id goes to the G-buffer's fiber field (picking
// returns it), its colour (RGBA8) is used when A > 0.
struct SurfaceSphere {
  vec4 center_radius;  // xyz centre (mm), w radius (mm, > 0)
  uint id;
  uint color;
  uint pad0;
  uint pad1;
};

// sphere_surface.comp: per pixel, the eye ray through the pixel centre
// (origin camera.eye, direction -pixelToEye) against every sphere: the
// nearer root t = -b - sqrt(r^2 - |h|^2) (b = (o - c).d, h = (o - c) - b d,
// the stable form), or the farther root where the nearer lies before the
// near plane (the eye inside the sphere); the hit's clip depth z/w from
// view_projection, kept where it lies in [0, 1] and is nearer than the
// surface texel's (ties: the smaller index). Writes depth, the sphere's id,
// the outward normal (also as the tangent: orientation colour follows the
// normal) and its colour.
struct SphereSurfacePush {
  uint64_t camera;   // CameraBlock
  uint64_t spheres;  // SurfaceSphere[count]
  uint64_t surface;  // SurfaceTexel per pixel (read and written)
  uint width;
  uint height;
  uint count;
  uint pad0;
};

// surface_merge.comp: per pixel, where the surface texel's depth is
// strictly less than the G-buffer's (ties: the lines stay), the G-buffer
// texel becomes {surface depth, surface fiber, kGBufferSurface | source,
// surface tangent}; except a translucent slice (kSurfaceSourceSlice, its
// colour's alpha below 255) over a drawn pixel, which leaves the texel as
// it is: shade.comp blends the slice's colour over it by the alpha. (So a
// translucent slice shows the fibers behind it, not other surfaces: the
// surface target holds one surface per pixel.)
struct SurfaceMergePush {
  uint64_t surface;  // SurfaceTexel per pixel
  uint64_t gbuffer;  // GBufferTexel per pixel (read and written)
  uint width;
  uint height;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
#include <cstddef>
static_assert(sizeof(fibscope::shader::SurfaceSphere) == 32, "");
static_assert(sizeof(fibscope::shader::SphereSurfacePush) == 40, "");
static_assert(offsetof(fibscope::shader::SphereSurfacePush, width) == 24, "");
static_assert(sizeof(fibscope::shader::SurfaceMergePush) == 24, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_SURFACE_PUSH_H
