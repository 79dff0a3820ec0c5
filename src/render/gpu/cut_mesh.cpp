#include "render/gpu/cut_mesh.h"

#include <utility>

#include "core/error.h"

namespace fibscope {

GpuCutMesh GpuCutMesh::upload(const gpu::VulkanContext& context, const TriangleMesh& mesh, const std::string& name) {
  if (mesh.triangles.empty() || mesh.positions.empty()) throw Error(name + ": the cut mesh has no triangles");
  if (mesh.triangles.size() >= (size_t(1) << 31)) throw Error(name + ": the cut mesh has too many triangles");
  for (const glm::uvec3& t : mesh.triangles)
    if (t.x >= mesh.positions.size() || t.y >= mesh.positions.size() || t.z >= mesh.positions.size())
      throw Error(name + ": a triangle of the cut mesh names a vertex it does not have");
  GpuCutMesh g;
  g.context_ = &context;
  try {
    const size_t position_bytes = mesh.positions.size() * sizeof(glm::vec3);
    const size_t triangle_bytes = mesh.triangles.size() * sizeof(glm::uvec3);
    static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::uvec3) == 12, "tightly packed x, y, z");
    g.positions_ = gpu::createBuffer(context, position_bytes, gpu::MemoryUse::DeviceLocal);
    g.triangles_ = gpu::createBuffer(context, triangle_bytes, gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context, g.positions_, mesh.positions.data(), position_bytes);
    gpu::uploadToBuffer(context, g.triangles_, mesh.triangles.data(), triangle_bytes);
  } catch (...) {
    g.release();
    throw;
  }
  g.triangle_count_ = uint32_t(mesh.triangles.size());
  return g;
}

GpuCutMesh::~GpuCutMesh() { release(); }

GpuCutMesh::GpuCutMesh(GpuCutMesh&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)),
      positions_(std::exchange(other.positions_, {})),
      triangles_(std::exchange(other.triangles_, {})),
      triangle_count_(std::exchange(other.triangle_count_, 0)) {}

GpuCutMesh& GpuCutMesh::operator=(GpuCutMesh&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    positions_ = std::exchange(other.positions_, {});
    triangles_ = std::exchange(other.triangles_, {});
    triangle_count_ = std::exchange(other.triangle_count_, 0);
  }
  return *this;
}

void GpuCutMesh::release() {
  if (!context_) return;
  gpu::destroyBuffer(*context_, positions_);
  gpu::destroyBuffer(*context_, triangles_);
  triangle_count_ = 0;
}

}  // namespace fibscope
