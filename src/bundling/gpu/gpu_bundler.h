// Fiber bundling on the GPU (FiberVisualizer section 7): the model's
// points and the plan of bundling/bundle_setup.h go up once, the passes of
// shared/bundling.h run per iteration (one submission each, so a caller
// can report progress between them), the bundled points come back with
// the model's own offsets. Deterministic: integer counts, fixed sums.
//
// Device memory: 12 B per point twice (in, out), 8 B per fiber, 52 B per
// sample (three vec4 copies, its fiber), 24 B per voxel (count, two
// density buffers, a vec4 gradient). bytes() says what one load holds.
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

class GpuBundler {
 public:
  // Makes the pipelines (throws Error when they cannot be made).
  explicit GpuBundler(const gpu::VulkanContext& context);
  ~GpuBundler();
  GpuBundler(const GpuBundler&) = delete;
  GpuBundler& operator=(const GpuBundler&) = delete;

  // Uploads `tractogram` (setup = planBundling(tractogram, params)) and
  // resamples it. Throws Error when memory runs out.
  void load(const Tractogram& tractogram, const BundleSetup& setup, const BundleParams& params);
  // One iteration at kernel radius `radius` (voxels): count, density x y z,
  // gradient, advection, smoothing. Submits and waits.
  void iterate(double radius);
  // Relaxation (alpha = params.relaxation) and mapping back: the bundled
  // points, x y z per point of the loaded tractogram. Submits and waits.
  std::vector<float> finish();

  // For tests: the state after load / the last iterate (downloaded).
  std::vector<glm::vec4> originalSamples() const;
  std::vector<glm::vec4> samples() const;   // current (after smoothing)
  std::vector<glm::vec4> advected() const;  // after the last advection
  std::vector<uint32_t> counts() const;     // anisotropic: the splat's fixed-point density
  std::vector<float> density() const;       // after the z pass (isotropic)
  std::vector<glm::vec4> gradient() const;

  uint64_t bytes() const;  // device memory of the loaded model
  // GPU milliseconds of each pass name, summed since load().
  const std::vector<gpu::PassTime>& passTimes() const { return times_; }

 private:
  void release();
  void addTimes();
  const gpu::VulkanContext& context_;
  BundlePipelines pipelines_;
  gpu::GpuTimer timer_;
  gpu::Buffer points_, point_offsets_, sample_offsets_, sample_fiber_, original_, current_, scratch_;
  gpu::Buffer counts_, density_, density_tmp_, gradient_, moved_;
  BundleSetup setup_;
  BundleParams params_;
  uint32_t fibers_ = 0;
  uint64_t points_count_ = 0;
  std::vector<gpu::PassTime> times_;
};

// A whole run on the GPU: planBundling, load, params.iterations iterations
// (`progress` called after each with the iterations done), finish.
std::vector<float> bundleOnGpu(const gpu::VulkanContext& context, const Tractogram& tractogram,
                               const BundleParams& params, const std::function<void(uint32_t done)>& progress = {},
                               std::vector<gpu::PassTime>* times = nullptr, uint64_t* device_bytes = nullptr);

}  // namespace fibscope
