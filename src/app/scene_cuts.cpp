#include "app/scene_cuts.h"

#include <cstdio>

#include "core/error.h"
#include "select/cut_mesh.h"
#include "select/cuts.h"
#include "select/roi_set.h"
#include "shared/cut_mesh.h"

namespace fibscope {

SceneCuts::SceneCuts(const gpu::VulkanContext& context, const RenderCliOptions& o) {
  std::vector<MeshCut> cuts;
  if (!o.criteria.roi_set.empty()) cuts = cutSet(loadRoiSet(o.criteria.roi_set)).meshes;
  for (const std::string& spec : o.cut_meshes) {
    try {
      cuts.push_back(parseMeshCut(spec));
    } catch (const Error& e) {
      throw Error(std::string("--cut-mesh ") + e.what());
    }
  }
  if (cuts.size() > shader::kMaxCutMeshes)
    throw Error("--cut-mesh: at most " + std::to_string(shader::kMaxCutMeshes) + " meshes, got " +
                std::to_string(cuts.size()));
  for (const MeshCut& cut : cuts) {
    const TriangleMesh mesh = cutMeshFromSpec(cut.spec);
    const std::string warning = closureWarning(checkClosure(mesh), cut.spec);
    if (!warning.empty()) std::fprintf(stderr, "fibscope: warning: %s\n", warning.c_str());
    meshes_.push_back(GpuCutMesh::upload(context, mesh, cut.spec));
    cull_inside_.push_back(cut.cull_inside);
  }
}

void SceneCuts::apply(GpuScene& scene) const {
  for (size_t i = 0; i < meshes_.size(); ++i) scene.cut_meshes.push_back({&meshes_[i], cull_inside_[i]});
}

}  // namespace fibscope
