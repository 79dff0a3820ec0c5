#include "bundling/gpu/gpu_bundler.h"

#include <algorithm>

#include "core/error.h"
#include "gpu/pass_scope.h"
#include "gpu/submit.h"

namespace fibscope {

namespace {

template <typename T>
std::vector<T> download(const gpu::VulkanContext& context, const gpu::Buffer& buffer, uint64_t count) {
  std::vector<T> out(count);
  if (count > 0) gpu::downloadFromBuffer(context, buffer, out.data(), count * sizeof(T));
  return out;
}

// Before the passes of a new submission touch what earlier ones wrote.
void afterEarlierWork(VkCommandBuffer cmd) {
  gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                     gpu::kStorageReadWrite | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                     gpu::kStorageReadWrite | VK_ACCESS_2_TRANSFER_WRITE_BIT);
}

}  // namespace

GpuBundler::GpuBundler(const gpu::VulkanContext& context, const GpuBundlerOptions& options)
    : context_(context), options_(options) {
  try {
    pipelines_ = createBundlePipelines(context);
    timer_ = gpu::createGpuTimer(context, 16);
  } catch (...) {
    release();
    throw;
  }
}

GpuBundler::~GpuBundler() { release(); }

void GpuBundler::releaseBuffers() {
  for (gpu::Buffer* b : {&points_, &point_offsets_, &sample_offsets_, &sample_fiber_, &original_, &current_, &scratch_,
                         &counts_, &density_, &density_tmp_, &gradient_, &cell_means_, &structure_})
    gpu::destroyBuffer(context_, *b);
}

void GpuBundler::release() {
  vkDeviceWaitIdle(context_.device());
  releaseBuffers();
  gpu::destroyGpuTimer(context_, timer_);
  destroyBundlePipelines(context_, pipelines_);
}

uint64_t GpuBundler::bytes() const {
  uint64_t total = 0;
  for (const gpu::Buffer* b : {&points_, &point_offsets_, &sample_offsets_, &sample_fiber_, &original_, &current_,
                               &scratch_, &counts_, &density_, &density_tmp_, &gradient_, &cell_means_, &structure_})
    total += b->size;
  return total;
}

std::vector<uint32_t> GpuBundler::planChunks(const Tractogram& t, uint64_t* most_points) const {
  const uint64_t limit = std::max<uint64_t>(options_.chunk_bytes / 12, 1);
  std::vector<uint32_t> firsts;
  *most_points = 0;
  uint32_t f = 0;
  while (f < fibers_) {
    firsts.push_back(f);
    const uint64_t base = t.offsets[f];
    uint32_t end = f + 1;  // at least one fiber, however long
    while (end < fibers_ && t.offsets[end + 1] - base <= limit) ++end;
    *most_points = std::max<uint64_t>(*most_points, t.offsets[end] - base);
    f = end;
  }
  firsts.push_back(fibers_);
  return firsts;
}

shader::BundleFiberPush GpuBundler::chunkPush(const Tractogram& t, size_t chunk) const {
  shader::BundleFiberPush push{};
  push.points = points_.address;
  push.moved = points_.address;
  push.point_offsets = point_offsets_.address;
  push.sample_offsets = sample_offsets_.address;
  push.fiber_first = chunks_[chunk];
  push.fiber_count = chunks_[chunk + 1] - chunks_[chunk];
  push.point_base = uint32_t(t.offsets[chunks_[chunk]]);
  return push;
}

void GpuBundler::load(const Tractogram& t, const BundleSetup& setup, const BundleParams& params) {
  releaseBuffers();
  times_.clear();
  setup_ = setup;
  params_ = params;
  fibers_ = uint32_t(t.streamlineCount());
  points_count_ = t.pointCount();
  if (setup.sample_offsets.size() != t.streamlineCount() + 1) throw Error("bundling: the plan is not this model's");
  if (points_count_ > UINT32_MAX) throw Error("bundling: more than 2^32 points in one model");
  std::vector<uint32_t> point_offsets(t.offsets.begin(), t.offsets.end());
  std::vector<uint32_t> sample_fiber(setup.sampleCount());
  for (uint32_t f = 0; f < fibers_; ++f)
    std::fill(sample_fiber.begin() + setup.sample_offsets[f], sample_fiber.begin() + setup.sample_offsets[f + 1], f);
  uint64_t chunk_points = 0;
  chunks_ = planChunks(t, &chunk_points);
  const uint64_t samples = std::max<uint64_t>(setup.sampleCount(), 1);
  const uint64_t voxels = setup.grid.voxelCount();
  const bool isotropic = params.mode != BundleMode::Anisotropic;
  auto make = [&](gpu::Buffer& b, uint64_t bytes) {
    b = gpu::createBuffer(context_, std::max<uint64_t>(bytes, 16), gpu::MemoryUse::DeviceLocal);
  };
  make(points_, chunk_points * 12);
  make(point_offsets_, point_offsets.size() * 4);
  make(sample_offsets_, setup.sample_offsets.size() * 4);
  make(sample_fiber_, samples * 4);
  make(original_, samples * 16);
  make(current_, samples * 16);
  make(scratch_, samples * 16);
  make(counts_, voxels * 4);
  if (isotropic) make(density_, voxels * 4);
  if (params.structure_aware) {
    const uint64_t cells = bundleStructureGrid(setup.grid, bundleStructureCell(params)).voxelCount();
    make(cell_means_, cells * 4);
    make(structure_, cells * 24);
  }
  if (options_.keep_stages) {
    make(density_tmp_, voxels * 4);
    make(gradient_, voxels * 16);
  }
  gpu::uploadToBuffer(context_, point_offsets_, point_offsets.data(), point_offsets.size() * 4);
  gpu::uploadToBuffer(context_, sample_offsets_, setup.sample_offsets.data(), setup.sample_offsets.size() * 4);
  if (!sample_fiber.empty()) gpu::uploadToBuffer(context_, sample_fiber_, sample_fiber.data(), sample_fiber.size() * 4);
  forEachChunk(t, nullptr, [&](VkCommandBuffer cmd, shader::BundleFiberPush push) {
    push.samples = original_.address;
    recordBundleResample(cmd, context_, pipelines_, push, &timer_);
  });
  gpu::submitOnce(context_, [&](VkCommandBuffer cmd) {
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    const VkBufferCopy copy{0, 0, samples * 16};
    vkCmdCopyBuffer(cmd, original_.buffer, current_.buffer, 1, &copy);
  });
}

void GpuBundler::iterate(double radius) {
  const shader::BundleGridBlock grid = bundleGridBlock(setup_.grid);
  shader::BundleSamplePush sample{};
  sample.grid = grid;
  sample.sample_fiber = sample_fiber_.address;
  sample.sample_offsets = sample_offsets_.address;
  sample.sample_count = setup_.sampleCount();
  sample.anchor_ends = params_.anchor_ends ? 1u : 0u;
  shader::BundleGridPush dens{};
  dens.grid = grid;
  dens.radius = float(radius);
  dens.inv_radius2 = float(1.0 / (radius * radius));
  gpu::submitOnce(context_, [&](VkCommandBuffer cmd) {
    gpu::resetGpuTimer(cmd, timer_);
    afterEarlierWork(cmd);
    vkCmdFillBuffer(cmd, counts_.buffer, 0, VK_WHOLE_SIZE, 0);
    gpu::recordBarrier(cmd, gpu::kTransferToCompute);
    shader::BundleGridPush g = dens;  // the density the gradient is taken of
    if (params_.mode == BundleMode::Anisotropic) {
      shader::BundleSamplePush splat = sample;
      splat.src = current_.address;
      splat.field = counts_.address;
      splat.radius_along = float(radius);
      splat.radius_across = float(radius * params_.anisotropy);
      recordBundleSplat(cmd, context_, pipelines_, splat, &timer_);
      g.src = counts_.address;
      g.src_is_count = 1;
      g.src_scale = 1.0f / shader::kBundleSplatScale;
    } else {
      shader::BundleSamplePush count = sample;
      count.src = current_.address;
      count.field = counts_.address;
      recordBundleCount(cmd, context_, pipelines_, count, &timer_);
      // counts -> density -> middle -> density; the middle pass writes into
      // the counts (done with by then) unless the tests keep them.
      const VkDeviceAddress middle = options_.keep_stages ? density_tmp_.address : counts_.address;
      const VkDeviceAddress from[3] = {counts_.address, density_.address, middle};
      const VkDeviceAddress to[3] = {density_.address, middle, density_.address};
      for (uint32_t axis = 0; axis < 3; ++axis) {
        shader::BundleGridPush p = dens;
        p.axis = axis;
        p.src_is_count = axis == 0 ? 1u : 0u;
        p.src = from[axis];
        p.dst = to[axis];
        recordBundleDensityAxis(cmd, context_, pipelines_, p, &timer_);
      }
      g.src = density_.address;
    }
    if (options_.keep_stages) {
      g.dst = gradient_.address;
      recordBundleGradient(cmd, context_, pipelines_, g, &timer_);
    }
    shader::BundleSamplePush advect = sample;
    if (params_.structure_aware) {
      const uint32_t cell = bundleStructureCell(params_);
      shader::BundleGridPush mean = g;
      mean.cell = cell;
      mean.dst = cell_means_.address;
      recordBundleStructureMean(cmd, context_, pipelines_, mean, &timer_);
      shader::BundleGridPush tensor{};
      tensor.grid = bundleGridBlock(bundleStructureGrid(setup_.grid, cell));
      tensor.src = cell_means_.address;
      tensor.dst = structure_.address;
      recordBundleStructure(cmd, context_, pipelines_, tensor, &timer_);
      advect.structure = structure_.address;
      advect.structure_cell = cell;
      advect.structure_power = params_.structure_power;
    }
    advect.src = current_.address;
    advect.dst = scratch_.address;
    advect.field = g.src;
    advect.field_is_count = g.src_is_count;
    advect.field_scale = g.src_scale;
    advect.step = float(bundleAdvectionStep(params_, setup_, radius));
    recordBundleAdvect(cmd, context_, pipelines_, advect, &timer_);
    shader::BundleSamplePush smooth = sample;
    smooth.src = scratch_.address;
    smooth.dst = current_.address;
    smooth.step = float(params_.smoothing);
    smooth.window = bundleSmoothingWindow(params_, setup_, radius);
    recordBundleSmooth(cmd, context_, pipelines_, smooth, &timer_);
  });
  addTimes();
}

std::vector<float> GpuBundler::finish(const Tractogram& t) {
  if (t.streamlineCount() != fibers_ || t.pointCount() != points_count_)
    throw Error("bundling: finish() was given another model than load()");
  shader::BundleSamplePush relax{};
  relax.grid = bundleGridBlock(setup_.grid);
  relax.src = current_.address;
  relax.dst = scratch_.address;
  relax.field = original_.address;
  relax.sample_count = setup_.sampleCount();
  relax.step = float(params_.relaxation);
  gpu::submitOnce(context_, [&](VkCommandBuffer cmd) {
    gpu::resetGpuTimer(cmd, timer_);
    afterEarlierWork(cmd);
    recordBundleRelax(cmd, context_, pipelines_, relax, &timer_);
  });
  addTimes();
  std::vector<float> out(points_count_ * 3);
  forEachChunk(t, out.data(), [&](VkCommandBuffer cmd, shader::BundleFiberPush map) {
    map.samples = scratch_.address;
    map.originals = original_.address;
    recordBundleMapBack(cmd, context_, pipelines_, map, &timer_);
  });
  return out;
}

void GpuBundler::forEachChunk(const Tractogram& t, float* positions_out,
                              const std::function<void(VkCommandBuffer, shader::BundleFiberPush)>& record) {
  for (size_t c = 0; c + 1 < chunks_.size(); ++c) {
    const uint64_t first = t.offsets[chunks_[c]], count = t.offsets[chunks_[c + 1]] - first;
    gpu::uploadToBuffer(context_, points_, t.positions.data() + 3 * first, count * 12);
    gpu::submitOnce(context_, [&](VkCommandBuffer cmd) {
      gpu::resetGpuTimer(cmd, timer_);
      afterEarlierWork(cmd);
      record(cmd, chunkPush(t, c));
      if (positions_out)
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT | VK_PIPELINE_STAGE_2_HOST_BIT,
                           VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_HOST_READ_BIT);
    });
    addTimes();
    if (positions_out) gpu::downloadFromBuffer(context_, points_, positions_out + 3 * first, count * 12);
  }
}

void GpuBundler::addTimes() {
  for (const gpu::PassTime& t : gpu::readGpuTimer(context_, timer_)) {
    auto it = std::find_if(times_.begin(), times_.end(), [&](const gpu::PassTime& p) { return p.name == t.name; });
    if (it == times_.end())
      times_.push_back(t);
    else
      it->ms += t.ms;
  }
}

std::vector<glm::vec4> GpuBundler::originalSamples() const {
  return download<glm::vec4>(context_, original_, setup_.sampleCount());
}
std::vector<glm::vec4> GpuBundler::samples() const {
  return download<glm::vec4>(context_, current_, setup_.sampleCount());
}
std::vector<glm::vec4> GpuBundler::advected() const {
  return download<glm::vec4>(context_, scratch_, setup_.sampleCount());
}
std::vector<uint32_t> GpuBundler::counts() const {
  if (!options_.keep_stages) throw Error("bundling: counts() needs GpuBundlerOptions::keep_stages");
  return download<uint32_t>(context_, counts_, setup_.grid.voxelCount());
}
std::vector<float> GpuBundler::density() const {
  if (density_.size == 0) throw Error("bundling: no density grid (anisotropic: counts())");
  return download<float>(context_, density_, setup_.grid.voxelCount());
}
std::vector<glm::vec4> GpuBundler::gradient() const {
  if (!options_.keep_stages) throw Error("bundling: gradient() needs GpuBundlerOptions::keep_stages");
  return download<glm::vec4>(context_, gradient_, setup_.grid.voxelCount());
}

std::vector<float> GpuBundler::structure() const {
  if (structure_.size == 0) throw Error("bundling: no structure tensor (BundleParams::structure_aware is off)");
  return download<float>(context_, structure_,
                         6 * bundleStructureGrid(setup_.grid, bundleStructureCell(params_)).voxelCount());
}

std::vector<float> bundleOnGpu(const gpu::VulkanContext& context, const Tractogram& tractogram,
                               const BundleParams& params, const std::function<void(uint32_t done)>& progress,
                               std::vector<gpu::PassTime>* times, uint64_t* device_bytes,
                               const GpuBundlerOptions& options) {
  const BundleSetup setup = planBundling(tractogram, params);
  GpuBundler bundler(context, options);
  bundler.load(tractogram, setup, params);
  if (device_bytes) *device_bytes = bundler.bytes();
  for (uint32_t it = 0; it < params.iterations; ++it) {
    bundler.iterate(bundleRadius(params, it));
    if (progress) progress(it + 1);
  }
  std::vector<float> out = bundler.finish(tractogram);
  if (times) *times = bundler.passTimes();
  return out;
}

}  // namespace fibscope
