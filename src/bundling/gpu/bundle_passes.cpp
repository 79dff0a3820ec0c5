#include "bundling/gpu/bundle_passes.h"

#include <algorithm>

#include "gpu/pass_scope.h"

namespace fibscope {

namespace {

constexpr gpu::WorkgroupSize kGroup{shader::kBundleGroupSize};

template <typename Push>
void dispatch(VkCommandBuffer cmd, const gpu::VulkanContext& context, const gpu::ComputePipeline& pipeline,
              const Push& push, uint64_t items, gpu::GpuTimer* timer, const char* name) {
  gpu::PassScope pass(cmd, timer, name, gpu::kComputeToCompute);
  if (items == 0) return;
  const gpu::DispatchGrid grid =
      gpu::dispatchGrid(context, (items + shader::kBundleGroupSize - 1) / shader::kBundleGroupSize);
  gpu::recordDispatch(cmd, pipeline, push, grid.x, grid.y);
}

uint64_t voxelsOf(const shader::BundleGridBlock& g) { return uint64_t(g.nx) * g.ny * g.nz; }

}  // namespace

BundlePipelines createBundlePipelines(const gpu::VulkanContext& context) {
  BundlePipelines p;
  try {
    const uint32_t fiber = sizeof(shader::BundleFiberPush), sample = sizeof(shader::BundleSamplePush),
                   grid = sizeof(shader::BundleGridPush);
    p.resample = gpu::createComputePipeline(context, "bundle_resample.comp", fiber, kGroup);
    p.count = gpu::createComputePipeline(context, "bundle_count.comp", sample, kGroup);
    p.density = gpu::createComputePipeline(context, "bundle_density.comp", grid, kGroup);
    p.gradient = gpu::createComputePipeline(context, "bundle_gradient.comp", grid, kGroup);
    p.advect = gpu::createComputePipeline(context, "bundle_advect.comp", sample, kGroup);
    p.smooth = gpu::createComputePipeline(context, "bundle_smooth.comp", sample, kGroup);
    p.relax = gpu::createComputePipeline(context, "bundle_relax.comp", sample, kGroup);
    p.map_back = gpu::createComputePipeline(context, "bundle_map_back.comp", fiber, kGroup);
    p.splat = gpu::createComputePipeline(context, "bundle_splat.comp", sample, kGroup);
    p.structure_mean = gpu::createComputePipeline(context, "bundle_structure_mean.comp", grid, kGroup);
    p.structure = gpu::createComputePipeline(context, "bundle_structure.comp", grid, kGroup);
  } catch (...) {
    destroyBundlePipelines(context, p);
    throw;
  }
  return p;
}

void destroyBundlePipelines(const gpu::VulkanContext& context, BundlePipelines& p) {
  for (gpu::ComputePipeline* c :
       {&p.resample, &p.count, &p.density, &p.gradient, &p.advect, &p.smooth, &p.relax, &p.map_back, &p.splat,
        &p.structure_mean, &p.structure})
    gpu::destroyComputePipeline(context, *c);
}

void recordBundleResample(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                          const shader::BundleFiberPush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.resample, push, push.fiber_count, timer, "bundle resample");
}
void recordBundleMapBack(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                         const shader::BundleFiberPush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.map_back, push, push.fiber_count, timer, "bundle map back");
}
void recordBundleCount(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                       const shader::BundleSamplePush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.count, push, push.sample_count, timer, "bundle count");
}
void recordBundleAdvect(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                        const shader::BundleSamplePush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.advect, push, push.sample_count, timer, "bundle advect");
}
void recordBundleSmooth(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                        const shader::BundleSamplePush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.smooth, push, push.sample_count, timer, "bundle smooth");
}
void recordBundleSplat(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                       const shader::BundleSamplePush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.splat, push, push.sample_count, timer, "bundle splat");
}
void recordBundleRelax(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                       const shader::BundleSamplePush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.relax, push, push.sample_count, timer, "bundle relax");
}
void recordBundleDensityAxis(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                             const shader::BundleGridPush& push, gpu::GpuTimer* timer) {
  static const char* const kNames[3] = {"bundle density x", "bundle density y", "bundle density z"};
  dispatch(cmd, context, p.density, push, voxelsOf(push.grid), timer, kNames[push.axis % 3]);
}
void recordBundleGradient(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                          const shader::BundleGridPush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.gradient, push, voxelsOf(push.grid), timer, "bundle gradient");
}
void recordBundleStructureMean(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                               const shader::BundleGridPush& push, gpu::GpuTimer* timer) {
  const uint32_t c = std::max(push.cell, 1u);
  const uint64_t cells = uint64_t((push.grid.nx + c - 1) / c) * ((push.grid.ny + c - 1) / c) * ((push.grid.nz + c - 1) / c);
  dispatch(cmd, context, p.structure_mean, push, cells, timer, "bundle structure mean");
}
void recordBundleStructure(VkCommandBuffer cmd, const gpu::VulkanContext& context, const BundlePipelines& p,
                           const shader::BundleGridPush& push, gpu::GpuTimer* timer) {
  dispatch(cmd, context, p.structure, push, voxelsOf(push.grid), timer, "bundle structure tensor");
}

}  // namespace fibscope
