#include "app/viewer/viewer_anatomy.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>

#include "render/anatomy_slices.h"

namespace fibscope {

bool isNiftiPath(std::string_view path) {
  auto endsWith = [&](std::string_view suffix) {
    if (path.size() < suffix.size()) return false;
    for (size_t i = 0; i < suffix.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(path[path.size() - suffix.size() + i])) != suffix[i]) return false;
    return true;
  };
  return endsWith(".nii") || endsWith(".nii.gz");
}

void stepActiveSlice(ViewerState& state, double voxels) {
  if (!state.anatomy.loaded()) return;
  const int axis = int(state.settings.active_slice);
  const double last = double(state.anatomy.dims[axis] - 1);
  const double moved = std::clamp(double(slicePosition(state.settings, axis)) + voxels, 0.0, last);
  setSlicePosition(state.settings, axis, float(moved));
}

void ViewerAnatomy::load(const gpu::VulkanContext& context, const std::string& path, ViewerState& state,
                         const std::function<bool(std::string_view)>& given) {
  show(context, path, loadAnatomyVolume(path), state, given);
}

void ViewerAnatomy::startLoad(const std::string& path) {
  // A future from std::async joins in its destructor: an earlier load
  // still reading is waited for here rather than left running.
  pending_ = std::async(std::launch::async, [path] { return loadAnatomyVolume(path); });
  pending_path_ = path;
}

bool ViewerAnatomy::poll(const gpu::VulkanContext& context, ViewerState& state) {
  if (!pending_.valid() || pending_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
  const std::string path = pending_path_;
  pending_path_.clear();
  const NiftiVolume volume = pending_.get();  // throws the reader's Error
  show(context, path, volume, state, nullptr);
  return true;
}

void ViewerAnatomy::show(const gpu::VulkanContext& context, const std::string& path, const NiftiVolume& volume,
                         ViewerState& state, const std::function<bool(std::string_view)>& given) {
  auto fresh = std::make_unique<GpuAnatomy>(GpuAnatomy::upload(context, volume));
  fitAnatomySettings(state.settings, fresh->grid(), fresh->robustRange(),
                     given ? given : [](std::string_view) { return false; });
  AnatomyInfo info;
  info.path = path;
  for (int a = 0; a < 3; ++a) {
    info.dims[a] = volume.dims[a];
    info.voxel_mm[a] = volume.voxel_size_mm[a];
  }
  info.min = volume.min;
  info.max = volume.max;
  info.robust_min = fresh->robustRange().min;
  info.robust_max = fresh->robustRange().max;
  state.anatomy = info;
  volume_ = std::move(fresh);
}

void ViewerAnatomy::unload(ViewerState& state) {
  if (pending_.valid()) pending_.wait();
  pending_ = {};
  pending_path_.clear();
  volume_.reset();
  state.anatomy = AnatomyInfo{};
}

Camera ViewerAnatomy::inView(const Camera& camera) const {
  if (!gpu()) return camera;
  const std::array<Vec3d, 8> corners = volumeCorners(volume_->grid());
  return enclosingDepthRange(camera, corners);
}

}  // namespace fibscope
