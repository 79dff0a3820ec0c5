// The scene table: which datasets a frame draws and where each one's
// fiblets and fibers start in the scene-global numbering (DESIGN.md
// section 6; render/gpu/scene_table.h builds it, the frame renderer
// uploads it with the camera block each frame).
//
// Several models are drawn into one visibility buffer. Each drawn dataset
// i gets fiblet_base_i and fiber_base_i, the prefix sums of the fiblet and
// fiber counts of the datasets before it. The rasters put the GLOBAL
// fiblet (fiblet_base + local fiblet) into the visibility key, so the
// nearest fiber wins across models with one atomicMin as for one model, and
// equal depths still resolve to the smaller (dataset, fiber, point). The
// resolve maps the global fiblet back to its dataset through this table and
// writes the GLOBAL fiber (fiber_base + local fiber) into the G-buffer, so
// per-fiber attributes (GpuScene::fiber_scalars, selection_bits) are one
// array over the scene's fibers.
//
// The key holds 28 fiblet bits (render_config.h: kMaxFiblets), so a scene
// is limited to 2^28 fiblets in all; the table to kMaxSceneDatasets
// entries (a viewer shows a handful; the resolve scans the bases).
#ifndef FIBSCOPE_SHADERS_SHARED_SCENE_TABLE_H
#define FIBSCOPE_SHADERS_SHARED_SCENE_TABLE_H

#include "shared/glsl_cpp.h"

#ifdef __cplusplus
#include <cstddef>
#define SCENE_CONST inline constexpr
#else
#define SCENE_CONST const
#endif

SHADER_NAMESPACE_BEGIN

SCENE_CONST uint kMaxSceneDatasets = 64u;

struct SceneDataset {
  uint64_t block;    // FibletDataset block (shared/fiblet_dataset.h)
  uint fiblet_base;  // global fiblet of the dataset's fiblet 0
  uint fiber_base;   // global fiber of the dataset's fiber 0
};

// The buffer: the header, then `count` SceneDataset entries in increasing
// fiblet_base (and fiber_base) order.
struct SceneTableHeader {
  uint count;
  uint fiblet_count;  // the scene's total
  uint fiber_count;   // the scene's total
  uint pad;
};

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::SceneDataset) == 16, "std430: uint64 first, two uints");
static_assert(sizeof(fibscope::shader::SceneTableHeader) == 16, "the entries start 8-byte aligned");
static_assert(offsetof(fibscope::shader::SceneDataset, fiblet_base) == 8, "");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_SCENE_TABLE_H
