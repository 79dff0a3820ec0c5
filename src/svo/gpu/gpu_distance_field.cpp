#include "svo/gpu/gpu_distance_field.h"

#include <algorithm>
#include <chrono>

#include "gpu/compute_pipeline.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"
#include "shared/distance_field.h"
#include "shared/svo.h"
#include "svo/gpu/gpu_svo.h"

namespace fibscope {

GpuDistanceField buildDistanceFieldGpu(const gpu::VulkanContext& context, const GpuTubes& tubes,
                                       const DistanceFieldGrid& grid) {
  const auto start = std::chrono::steady_clock::now();
  GpuDistanceField field;
  field.grid = grid;
  gpu::ComputePipeline voxelize, finalize;
  try {
    field.values = gpu::createBuffer(context, std::max<uint64_t>(grid.bytes(), 4), gpu::MemoryUse::DeviceLocal);
    voxelize = createSvoVoxelizePipeline(context);
    finalize = gpu::createComputePipeline(context, "df_finalize.comp", sizeof(shader::DfFinalizePush),
                                          gpu::WorkgroupSize{shader::kDfFinalizeGroupSize});
    gpu::submitOnce(context, [&](VkCommandBuffer cmd) {
      vkCmdFillBuffer(cmd, field.values.buffer, 0, VK_WHOLE_SIZE, shader::kSvoFar);
      gpu::recordBarrier(cmd, gpu::kTransferToCompute);
      if (tubes.segment_count > 0) {
        // The octree's voxelisation with a wide band, x by y by z in one
        // slab (rows: the y extent).
        shader::SvoVoxelizePush vp{};
        vp.field = field.values.address;
        vp.origin_x = grid.origin.x;
        vp.origin_y = grid.origin.y;
        vp.origin_z = grid.origin.z;
        vp.voxel = grid.voxel;
        vp.side = grid.size.x;
        vp.rows = grid.size.y;
        vp.slab_z0 = 0;
        vp.slab_depth = grid.size.z;
        vp.band = grid.band;
        vp.curved = 0;
        recordSvoVoxelize(context, cmd, voxelize, tubes, vp);
        gpu::computeToComputeBarrier(cmd);
      }
      shader::DfFinalizePush fp{};
      fp.field = field.values.address;
      fp.count = uint32_t(grid.voxels());
      fp.band = grid.band;
      const gpu::DispatchGrid g = gpu::dispatchGrid(
          context, (grid.voxels() + shader::kDfFinalizeGroupSize - 1) / shader::kDfFinalizeGroupSize);
      gpu::recordDispatch(cmd, finalize, fp, g.x, g.y);
    });
  } catch (...) {
    gpu::destroyComputePipeline(context, finalize);
    gpu::destroyComputePipeline(context, voxelize);
    destroyDistanceField(context, field);
    throw;
  }
  gpu::destroyComputePipeline(context, finalize);
  gpu::destroyComputePipeline(context, voxelize);
  field.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return field;
}

void destroyDistanceField(const gpu::VulkanContext& context, GpuDistanceField& field) {
  gpu::destroyBuffer(context, field.values);
}

std::vector<float> downloadDistanceField(const gpu::VulkanContext& context, const GpuDistanceField& field) {
  std::vector<float> values(field.grid.voxels());
  gpu::downloadFromBuffer(context, field.values, values.data(), values.size() * sizeof(float));
  return values;
}

}  // namespace fibscope
