// Fiber bundling on the GPU (FiberVisualizer section 7): the plan of
// bundling/bundle_setup.h goes up once, the model's points a chunk of whole
// fibers at a time (resampled, then mapped back in place at the end: they
// are not on the device during the iterations), the passes of
// shared/bundling.h run per iteration (one submission each, so a caller can
// report progress between them), the bundled points come back with the
// model's own offsets. Deterministic: integer counts, fixed sums.
//
// Device memory: 8 B per fiber; 52 B per sample (three vec4 copies, its
// fiber); 8 B per voxel isotropic (counts, density; the separable density's
// middle pass writes into the counts), 4 B anisotropic (the splat's
// density); structure-aware, 28 B a cell of the structure tensor (its
// mean density, its 6 floats: at most 3.5 B a voxel); one chunk of points (GpuBundlerOptions::chunk_bytes, or the
// longest fiber). No gradient grid: the advection takes the gradient from
// the density at the voxels around each sample. bytes() says what one load
// holds (the staging copies of the chunks are host memory).
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bundling/bundle_params.h"
#include "bundling/bundle_setup.h"
#include "bundling/gpu/bundle_passes.h"
#include "core/tractogram.h"
#include "gpu/buffer.h"
#include "gpu/gpu_timer.h"
#include "gpu/vulkan_context.h"

namespace fibscope {

struct GpuBundlerOptions {
  // Points on the device at a time (resampling, mapping back): whole fibers
  // up to this many bytes (12 a point), more when one fiber needs it.
  uint64_t chunk_bytes = uint64_t(64) << 20;
  // For the tests of each stage: keep the counts apart from the density
  // passes' scratch and write the gradient grid (the advection does not
  // read it), so counts() and gradient() show this iteration's. 20 B a
  // voxel more.
  bool keep_stages = false;
};

class GpuBundler {
 public:
  // Makes the pipelines (throws Error when they cannot be made).
  explicit GpuBundler(const gpu::VulkanContext& context, const GpuBundlerOptions& options = {});
  ~GpuBundler();
  GpuBundler(const GpuBundler&) = delete;
  GpuBundler& operator=(const GpuBundler&) = delete;

  // Uploads `tractogram` (setup = planBundling(tractogram, params)) and
  // resamples it. Throws Error when memory runs out.
  void load(const Tractogram& tractogram, const BundleSetup& setup, const BundleParams& params);
  // One iteration at kernel radius `radius` (voxels): count, density x y z,
  // gradient, (structure tensor,) advection, smoothing. Submits and waits.
  void iterate(double radius);
  // Relaxation (alpha = params.relaxation) and mapping back: the bundled
  // points, x y z per point of `tractogram` (the one given to load). Submits
  // and waits, a chunk at a time.
  std::vector<float> finish(const Tractogram& tractogram);

  // For tests: the state after load / the last iterate (downloaded).
  std::vector<glm::vec4> originalSamples() const;
  std::vector<glm::vec4> samples() const;   // current (after smoothing)
  std::vector<glm::vec4> advected() const;  // after the last advection
  // keep_stages only (throw Error otherwise): the counts (anisotropic: the
  // splat's fixed-point density) and the gradient grid.
  std::vector<uint32_t> counts() const;
  std::vector<float> density() const;  // after the z pass (isotropic)
  std::vector<glm::vec4> gradient() const;
  // structure_aware only: the structure tensor of the last iteration, 6
  // floats a cell (xx xy xz yy yz zz; bundleStructureGrid's order).
  std::vector<float> structure() const;

  uint64_t bytes() const;  // device memory of the loaded model
  // GPU milliseconds of each pass name, summed since load().
  const std::vector<gpu::PassTime>& passTimes() const { return times_; }

 private:
  void release();
  void releaseBuffers();
  void addTimes();
  // The first fiber of each chunk, then the fiber count.
  std::vector<uint32_t> planChunks(const Tractogram& tractogram, uint64_t* most_points) const;
  shader::BundleFiberPush chunkPush(const Tractogram& tractogram, size_t chunk) const;
  // Each chunk's points uploaded into points_, then `record` (given the
  // chunk's push) submitted after the earlier work; with `positions_out`
  // (3 floats a point of the whole tractogram) points_ is read back into it
  // after each chunk (the map-back writes the moved points there in place).
  void forEachChunk(const Tractogram& tractogram, float* positions_out,
                    const std::function<void(VkCommandBuffer, shader::BundleFiberPush)>& record);
  const gpu::VulkanContext& context_;
  GpuBundlerOptions options_;
  BundlePipelines pipelines_;
  gpu::GpuTimer timer_;
  gpu::Buffer points_, point_offsets_, sample_offsets_, sample_fiber_, original_, current_, scratch_;
  gpu::Buffer counts_, density_, density_tmp_, gradient_;  // the last two: keep_stages
  gpu::Buffer cell_means_, structure_;                      // structure_aware
  BundleSetup setup_;
  BundleParams params_;
  uint32_t fibers_ = 0;
  uint64_t points_count_ = 0;
  std::vector<uint32_t> chunks_;
  std::vector<gpu::PassTime> times_;
};

// A whole run on the GPU: planBundling, load, params.iterations iterations
// (`progress` called after each with the iterations done), finish.
std::vector<float> bundleOnGpu(const gpu::VulkanContext& context, const Tractogram& tractogram,
                               const BundleParams& params, const std::function<void(uint32_t done)>& progress = {},
                               std::vector<gpu::PassTime>* times = nullptr, uint64_t* device_bytes = nullptr,
                               const GpuBundlerOptions& options = {});

}  // namespace fibscope
