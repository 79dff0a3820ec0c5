#include "app/viewer/viewer_cuts.h"

#include <set>

#include "core/error.h"
#include "select/cut_mesh.h"

namespace fibscope {

std::string ViewerCuts::prepare(const std::string& spec) {
  if (const auto it = held_.find(spec); it != held_.end()) return it->second.warning;
  const TriangleMesh mesh = cutMeshFromSpec(spec);
  Held held;
  held.warning = closureWarning(checkClosure(mesh), spec);
  held.mesh = GpuCutMesh::upload(context_, mesh, spec);
  failed_.erase(spec);
  return held_.emplace(spec, std::move(held)).first->second.warning;
}

void ViewerCuts::sync(DissectionState& state) {
  std::set<std::string> specs;
  for (const RoiCutMesh& m : state.set.cut_meshes) specs.insert(m.cut.spec);
  std::erase_if(held_, [&](const auto& kv) { return !specs.count(kv.first); });
  std::erase_if(failed_, [&](const auto& kv) { return !specs.count(kv.first); });
  state.cut_mesh_notes.clear();
  for (const std::string& spec : specs) {
    if (const auto f = failed_.find(spec); f != failed_.end()) {
      state.cut_mesh_notes[spec] = f->second;
      continue;
    }
    try {
      state.cut_mesh_notes[spec] = prepare(spec);
    } catch (const Error& e) {
      // A loaded set naming a file that is gone: the rest is drawn.
      failed_[spec] = std::string("not drawn: ") + e.what();
      state.cut_mesh_notes[spec] = failed_[spec];
    }
  }
}

void ViewerCuts::apply(const RoiSet& set, GpuScene& scene) const {
  for (const RoiCutMesh& m : set.cut_meshes) {
    if (!m.enabled || scene.cut_meshes.size() >= kMaxCutMeshes) continue;
    const auto it = held_.find(m.cut.spec);
    if (it != held_.end()) scene.cut_meshes.push_back({&it->second.mesh, m.cut.cull_inside});
  }
}

}  // namespace fibscope
