#include "render/gpu/anatomy.h"

#include <cfloat>
#include <cmath>
#include <cstring>
#include <algorithm>
#include <utility>

#include "core/error.h"
#include "render/gpu/staged_upload.h"

namespace fibscope {
namespace {

constexpr uint64_t kStagingBytes = uint64_t(16) << 20;

}  // namespace

GpuAnatomy GpuAnatomy::upload(const gpu::VulkanContext& context, const NiftiVolume& volume) {
  const uint64_t voxels = uint64_t(volume.dims.x) * uint64_t(volume.dims.y) * uint64_t(volume.dims.z);
  if (voxels == 0 || volume.values.size() != voxels) fail(volume.path, "no voxels to show");
  if (voxels > kMaxAnatomyVoxels)
    fail(volume.path, std::to_string(voxels) + " voxels, more than the " + std::to_string(kMaxAnatomyVoxels) +
                          " of an anatomical image");
  GpuAnatomy a;
  a.context_ = &context;
  a.path_ = volume.path;
  a.grid_ = anatomyGrid(volume);
  a.robust_ = robustValueRange(volume.values);
  a.min_ = volume.min;
  a.max_ = volume.max;
  // Converted as copied, through a bounded staging buffer (a volume may
  // be 512 MiB).
  const float* src = volume.values.data();
  // Ranges need not start or end on a float (uploadRandomAccess splits
  // by bytes).
  const ChunkSource source = [src](uint8_t* out, uint64_t offset, uint64_t bytes) {
    for (uint64_t b = offset; b < offset + bytes;) {
      const float x = src[b / sizeof(float)];
      const float v = std::isinf(x) ? (x > 0 ? FLT_MAX : -FLT_MAX) : x;
      const uint64_t within = b % sizeof(float), n = std::min<uint64_t>(sizeof(float) - within, offset + bytes - b);
      std::memcpy(out + (b - offset), reinterpret_cast<const uint8_t*>(&v) + within, size_t(n));
      b += n;
    }
  };
  gpu::Buffer staging;
  try {
    a.values_ = gpu::createBuffer(context, voxels * sizeof(float), gpu::MemoryUse::DeviceLocal);
    uploadRandomAccess(
        context,
        [&]() -> const gpu::Buffer& {
          if (!staging.buffer)
            staging = gpu::createBuffer(context, std::min<uint64_t>(voxels * sizeof(float), kStagingBytes),
                                        gpu::MemoryUse::Upload);
          return staging;
        },
        a.values_, voxels * sizeof(float), source, nullptr);
  } catch (const Error& e) {
    gpu::destroyBuffer(context, staging);
    fail(volume.path, std::string("cannot upload the volume: ") + e.what());
  }
  gpu::destroyBuffer(context, staging);
  return a;
}

GpuAnatomy::~GpuAnatomy() { release(); }

GpuAnatomy::GpuAnatomy(GpuAnatomy&& other) noexcept
    : context_(std::exchange(other.context_, nullptr)),
      values_(std::exchange(other.values_, {})),
      path_(std::move(other.path_)),
      grid_(other.grid_),
      robust_(other.robust_),
      min_(other.min_),
      max_(other.max_) {}

GpuAnatomy& GpuAnatomy::operator=(GpuAnatomy&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    values_ = std::exchange(other.values_, {});
    path_ = std::move(other.path_);
    grid_ = other.grid_;
    robust_ = other.robust_;
    min_ = other.min_;
    max_ = other.max_;
  }
  return *this;
}

void GpuAnatomy::release() {
  if (context_) gpu::destroyBuffer(*context_, values_);
  context_ = nullptr;
}

}  // namespace fibscope
