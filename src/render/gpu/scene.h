// What a frame draws (the input of FrameRenderer and of every frame stage).
#pragma once

#include <vulkan/vulkan.h>

#include <vector>

#include "render/gpu/cut_mesh.h"
#include "render/gpu/dataset.h"
#include "render/gpu/raw_tractogram.h"
#include "shared/surface_push.h"

namespace fibscope {

class GpuAnatomy;

// The fiblets of one or more datasets (compute pipeline), drawn together
// into one visibility buffer (the nearest fiber wins across datasets) with
// scene-global fiblet and fiber ids (render/gpu/scene_table.h: dataset i's
// fibers are fiber_base_i + its own), and, for the baselines, one
// tractogram as raw float vertices; surfaces drawn with them, whatever the
// pipeline. A pipeline whose input is missing is an Error when the frame is
// recorded.
struct GpuScene {
  GpuScene() = default;
  // One dataset (or none), as most callers draw.
  GpuScene(const GpuDataset* fiblets, const GpuRawTractogram* raw_vertices = nullptr) : raw(raw_vertices) {
    if (fiblets) datasets.push_back(fiblets);
  }

  std::vector<const GpuDataset*> datasets;  // in drawing order (none null); the scene's fiber ids follow it
  const GpuRawTractogram* raw = nullptr;    // lines and raw-compute (one tractogram)
  // Per-fiber attributes (src/render/gpu/fiber_attributes.h), indexed by
  // the G-buffer's fiber id (scene-global: for one dataset its own ids); 0
  // means none. Each must hold an entry for every fiber of the drawn
  // datasets (the raw tractogram's, for the baselines), e.g.
  // GpuSceneFiberLengths for the scalars.
  VkDeviceAddress fiber_scalars = 0;   // float per fiber (ColorMode::Scalar)
  VkDeviceAddress selection_bits = 0;  // uint words: fiber f selected when bit f % 32 of word f / 32 is set;
                                       // 0 also means an empty selection (nothing dimmed)
  // The fiber filter (select/gpu/gpu_fiber_filter.h): its kept bits over
  // the scene's fibers (the layout's for compute, the raw tractogram's
  // streamlines for the baselines), and for the raw-compute baseline a bit
  // per raw point. 0: every fiber drawn. Dropped fibers are not drawn at
  // all (no pixel, no pick).
  VkDeviceAddress kept_bits = 0;
  VkDeviceAddress kept_point_bits = 0;
  // Mesh cuts (shared/cut_mesh.h), at most shader::kMaxCutMeshes: each
  // closed mesh hides the fiber fragments inside it (cull_inside) or
  // outside it, in every pipeline; fiblets it hides wholly are culled.
  struct CutMesh {
    const GpuCutMesh* mesh = nullptr;
    bool cull_inside = true;
  };
  std::vector<CutMesh> cut_meshes;
  // Analytic spheres (world mm) drawn as surfaces with the lines, at most
  // shader::kMaxSurfaceSpheres; their ids land in the G-buffer's fiber field.
  std::vector<shader::SurfaceSphere> spheres;
  // An anatomical volume whose slices (RenderSettings::slice_*) are drawn
  // as surfaces with the lines (render/gpu/anatomy.h); null: none.
  const GpuAnatomy* anatomy = nullptr;
};

}  // namespace fibscope
