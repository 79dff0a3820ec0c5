// The dissection's mesh cuts on the GPU: each cut mesh spec of the ROI set
// (an OBJ file or a built-in shape) read, checked for closure and uploaded
// as a GpuCutMesh once, when it first appears in the set, then named in
// each frame's GpuScene.cut_meshes while it is enabled. Toggling a cut's
// side or enabling it again uploads nothing; a spec no longer in the set is
// freed at the next sync.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "app/viewer/dissection.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/cut_mesh.h"
#include "render/gpu/scene.h"

namespace fibscope {

class ViewerCuts {
 public:
  explicit ViewerCuts(const gpu::VulkanContext& context) : context_(context) {}

  // Reads and uploads the mesh of `spec` unless it is held already, and
  // returns its closure warning ("" when closed). Throws Error (one line
  // naming the spec or its file) for a bad built-in spec, an OBJ that
  // cannot be read or has no triangles; nothing is held then. Between
  // frames only.
  std::string prepare(const std::string& spec);
  // Between frames, with no frame in flight (a mesh no longer in the set is
  // destroyed): holds a mesh for every cut of the set (prepare; a spec that
  // fails is noted and not drawn) and fills state.cut_mesh_notes.
  void sync(DissectionState& state);
  // The enabled cuts held, in the set's order (at most kMaxCutMeshes), into
  // scene.cut_meshes. The meshes live until the next sync that drops them.
  void apply(const RoiSet& set, GpuScene& scene) const;

 private:
  struct Held {
    GpuCutMesh mesh;
    std::string warning;
  };
  const gpu::VulkanContext& context_;
  std::map<std::string, Held> held_;
  std::map<std::string, std::string> failed_;  // spec -> why it is not drawn (not retried until it leaves the set)
};

}  // namespace fibscope
