// A closed surface mesh on the GPU for a mesh cut (shared/cut_mesh.h,
// render/gpu/cut_mesh_stage.cpp): its vertices and triangles in device
// buffers, drawn each frame into the cut's front and back depth buffers.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "io/obj_mesh.h"

namespace fibscope {

class GpuCutMesh {
 public:
  GpuCutMesh() = default;
  // Uploads `mesh` (triangles outward: select/cut_mesh.h orientOutward).
  // Throws Error naming `name` for an empty mesh, an index out of range or
  // more than 2^31 triangles, or when memory runs out.
  static GpuCutMesh upload(const gpu::VulkanContext& context, const TriangleMesh& mesh, const std::string& name);
  ~GpuCutMesh();
  GpuCutMesh(GpuCutMesh&& other) noexcept;
  GpuCutMesh& operator=(GpuCutMesh&& other) noexcept;
  GpuCutMesh(const GpuCutMesh&) = delete;
  GpuCutMesh& operator=(const GpuCutMesh&) = delete;

  VkDeviceAddress positions() const { return positions_.address; }
  VkDeviceAddress triangles() const { return triangles_.address; }
  uint32_t triangleCount() const { return triangle_count_; }

 private:
  void release();
  const gpu::VulkanContext* context_ = nullptr;
  gpu::Buffer positions_, triangles_;
  uint32_t triangle_count_ = 0;
};

}  // namespace fibscope
