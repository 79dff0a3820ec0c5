// Mesh cuts (shared/cut_mesh.h): each of the scene's cut meshes drawn into
// its front and back depth buffers by cut_mesh_raster.comp, summarised per
// tile for the cull by cut_mesh_tiles.comp, and the camera block told where
// they are, before any geometry: the rasters discard what a cut hides, per
// fragment, and the cull skips fiblets a cut hides wholly.
#include <cstddef>
#include <string>

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "render/gpu/frame_stages.h"
#include "shared/cut_mesh.h"

namespace fibscope {
namespace {

class CutMeshStage final : public FrameStage {
 public:
  explicit CutMeshStage(const gpu::VulkanContext&) {}

  void destroy(const gpu::VulkanContext& context) override {
    gpu::destroyComputePipeline(context, raster_);
    gpu::destroyComputePipeline(context, tiles_pass_);
    gpu::destroyBuffer(context, depths_);
    gpu::destroyBuffer(context, tiles_);
  }
  uint32_t maxPasses() const override { return 1; }
  bool runs(const FrameContext& frame) const override { return !frame.scene.cut_meshes.empty(); }

  void check(const FrameContext& frame) const override {
    if (frame.scene.cut_meshes.size() > shader::kMaxCutMeshes)
      throw Error("render: at most " + std::to_string(shader::kMaxCutMeshes) + " cut meshes, got " +
                  std::to_string(frame.scene.cut_meshes.size()));
    for (const GpuScene::CutMesh& m : frame.scene.cut_meshes)
      if (!m.mesh || m.mesh->triangleCount() == 0) throw Error("render: a cut mesh without triangles");
  }

  void resize(const gpu::VulkanContext& context, uint32_t, uint32_t) override {
    gpu::destroyBuffer(context, depths_);
    gpu::destroyBuffer(context, tiles_);
  }

  void record(FrameContext& frame) override {
    const gpu::VulkanContext& context = frame.context;
    const std::vector<GpuScene::CutMesh>& meshes = frame.scene.cut_meshes;
    const uint32_t width = frame.targets.width, height = frame.targets.height;
    const uint64_t pixels = uint64_t(width) * height;
    const uint32_t tiles_x = (width + shader::kCutTileSize - 1) / shader::kCutTileSize;
    const uint32_t tiles_y = (height + shader::kCutTileSize - 1) / shader::kCutTileSize;
    if (raster_.pipeline == VK_NULL_HANDLE) {
      raster_ = gpu::createComputePipeline(context, "cut_mesh_raster.comp", sizeof(shader::CutMeshRasterPush),
                                           gpu::WorkgroupSize{shader::kCutRasterGroupSize});
      tiles_pass_ = gpu::createComputePipeline(context, "cut_mesh_tiles.comp", sizeof(shader::CutMeshTilesPush),
                                               gpu::WorkgroupSize{shader::kCutTileGroupSize});
    }
    // Sized for every mesh a frame may have, once per frame size.
    if (depths_.buffer == VK_NULL_HANDLE) {
      depths_ = gpu::createBuffer(context, 2 * pixels * shader::kMaxCutMeshes * sizeof(uint32_t),
                                  gpu::MemoryUse::DeviceLocal);
      tiles_ = gpu::createBuffer(context, uint64_t(tiles_x) * tiles_y * shader::kMaxCutMeshes * sizeof(shader::CutTile),
                                 gpu::MemoryUse::DeviceLocal);
    }
    // Read by the cull and the compute rasters, and by the lines' shaders.
    const gpu::PassBarrier after{VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                                 VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                                     VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                 gpu::kStorageReadWrite};
    gpu::PassScope pass(frame.cmd, frame.timer, "mesh cuts", after);
    // The setup stage's camera block write before this one's update of its
    // cut fields, and before the raster reads the block.
    gpu::memoryBarrier(frame.cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    shader::CutMeshFrame cuts{};
    cuts.depths = depths_.address;
    cuts.tiles = tiles_.address;
    cuts.mesh_count = uint32_t(meshes.size());
    cuts.tiles_x = tiles_x;
    cuts.tiles_y = tiles_y;
    for (size_t m = 0; m < meshes.size(); ++m)
      if (meshes[m].cull_inside) cuts.inside_bits |= 1u << m;
    vkCmdUpdateBuffer(frame.cmd, frame.targets.camera.buffer, offsetof(shader::CameraBlock, mesh_cuts), sizeof(cuts),
                      &cuts);
    vkCmdFillBuffer(frame.cmd, depths_.buffer, 0, 2 * pixels * meshes.size() * sizeof(uint32_t),
                    shader::kCutDepthNone);
    gpu::recordBarrier(frame.cmd, gpu::kTransferToCompute);
    for (size_t m = 0; m < meshes.size(); ++m) {
      shader::CutMeshRasterPush push{};
      push.camera = frame.targets.camera.address;
      push.positions = meshes[m].mesh->positions();
      push.triangles = meshes[m].mesh->triangles();
      push.front = depths_.address + 2 * m * pixels * sizeof(uint32_t);
      push.back = push.front + pixels * sizeof(uint32_t);
      push.triangle_count = meshes[m].mesh->triangleCount();
      const gpu::DispatchGrid grid = gpu::dispatchGrid(
          context, (push.triangle_count + shader::kCutRasterGroupSize - 1) / shader::kCutRasterGroupSize);
      gpu::recordDispatch(frame.cmd, raster_, push, grid.x, grid.y);
    }
    gpu::computeToComputeBarrier(frame.cmd);
    for (size_t m = 0; m < meshes.size(); ++m) {
      shader::CutMeshTilesPush push{};
      push.front = depths_.address + 2 * m * pixels * sizeof(uint32_t);
      push.back = push.front + pixels * sizeof(uint32_t);
      push.tiles = tiles_.address + m * uint64_t(tiles_x) * tiles_y * sizeof(shader::CutTile);
      push.width = width;
      push.height = height;
      push.tiles_x = tiles_x;
      push.tiles_y = tiles_y;
      const gpu::DispatchGrid grid = gpu::dispatchGrid(
          context, (uint64_t(tiles_x) * tiles_y + shader::kCutTileGroupSize - 1) / shader::kCutTileGroupSize);
      gpu::recordDispatch(frame.cmd, tiles_pass_, push, grid.x, grid.y);
    }
  }

 private:
  gpu::ComputePipeline raster_, tiles_pass_;  // made at the first frame with a cut mesh
  gpu::Buffer depths_, tiles_;               // for kMaxCutMeshes meshes at the frame's size
};

}  // namespace

std::unique_ptr<FrameStage> makeCutMeshStage(const gpu::VulkanContext& context) {
  return std::make_unique<CutMeshStage>(context);
}

}  // namespace fibscope
