// The mesh cuts of what `render` and `bench` draw: --cut-mesh SPEC:inside|
// outside (select/cuts.h; an OBJ file or a built-in box, oriented box or
// sphere) and those of --roi-set's set, read, checked for closure (an open
// mesh is a warning: the cut may be approximate) and uploaded once, then
// named in each frame's GpuScene.
#pragma once

#include <string>
#include <vector>

#include "app/render_options.h"
#include "render/gpu/cut_mesh.h"
#include "render/gpu/scene.h"

namespace fibscope {

class SceneCuts {
 public:
  SceneCuts() = default;
  // Throws Error (one line naming the spec or file) for a spec that does
  // not parse, an OBJ that cannot be read or has no triangles, or more than
  // shader::kMaxCutMeshes meshes; prints each closure warning.
  SceneCuts(const gpu::VulkanContext& context, const RenderCliOptions& options);
  void apply(GpuScene& scene) const;
  bool empty() const { return meshes_.empty(); }

 private:
  std::vector<GpuCutMesh> meshes_;
  std::vector<bool> cull_inside_;
};

}  // namespace fibscope
