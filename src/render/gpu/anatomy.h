// An anatomical volume on the device (DESIGN.md section 2): its values as
// one float per voxel (i fastest, then j, then k) in a device-local buffer,
// with the grid and affine the slices need (render/anatomy_slices.h) and
// its value ranges. The anatomy stage draws it (GpuScene::anatomy).
#pragma once

#include <string>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "io/nifti_volume.h"
#include "render/anatomy_slices.h"

namespace fibscope {

class GpuAnatomy {
 public:
  GpuAnatomy() = default;
  ~GpuAnatomy();
  GpuAnatomy(GpuAnatomy&& other) noexcept;
  GpuAnatomy& operator=(GpuAnatomy&& other) noexcept;
  GpuAnatomy(const GpuAnatomy&) = delete;
  GpuAnatomy& operator=(const GpuAnatomy&) = delete;

  // Uploads the volume's values (+-infinity as +-FLT_MAX, so that the
  // trilinear mix stays finite; NaN kept: no value, nothing drawn there).
  // Throws Error "PATH: ..." (one line) for an empty volume, one of more
  // than kMaxAnatomyVoxels voxels, or when device memory runs out.
  static GpuAnatomy upload(const gpu::VulkanContext& context, const NiftiVolume& volume);

  bool empty() const { return !values_.buffer; }
  const std::string& path() const { return path_; }
  const AnatomyGrid& grid() const { return grid_; }
  const gpu::Buffer& values() const { return values_; }
  // robustValueRange of the values, and their finite min and max (NaN when
  // none is finite).
  ValueRange robustRange() const { return robust_; }
  float minValue() const { return min_; }
  float maxValue() const { return max_; }

 private:
  void release();

  const gpu::VulkanContext* context_ = nullptr;
  gpu::Buffer values_;
  std::string path_;
  AnatomyGrid grid_;
  ValueRange robust_;
  float min_ = 0, max_ = 0;
};

}  // namespace fibscope
