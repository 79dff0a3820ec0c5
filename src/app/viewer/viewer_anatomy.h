// The viewer's anatomical image (DESIGN.md section 2): one NIfTI volume at a
// time, shown as slices by every frame (GpuScene::anatomy), loaded from the
// anatomy panel's path entry, a dropped .nii/.nii.gz, a script's `anatomy
// FILE` or `view --anatomy FILE`; and the slice keys' rule. The file is
// read and decompressed on a thread of its own (startLoad/poll) while
// frames go on: a 0.7 mm .nii.gz takes seconds; only the upload is on the
// frame's thread.
#pragma once

#include <functional>
#include <future>
#include <memory>
#include <string>
#include <string_view>

#include "app/viewer/viewer_state.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "io/nifti_volume.h"
#include "render/gpu/anatomy.h"

namespace fibscope {

// .nii or .nii.gz (any case): an anatomical image rather than a tractogram.
bool isNiftiPath(std::string_view path);

// Moves the active slice of state.settings by `voxels`, clamped to the
// loaded volume's [0, dim - 1]; nothing without a volume.
void stepActiveSlice(ViewerState& state, double voxels);

class ViewerAnatomy {
 public:
  // Reads and uploads `path` (the device must not be using the current
  // volume: call between frames), replacing the volume shown; state.anatomy
  // describes it and state.settings' slices go to its centre and the
  // display range to its robust range, except the settings `given` names
  // (null: none). Throws Error "PATH: ..." (one line) and keeps the current
  // volume when the file cannot be shown.
  void load(const gpu::VulkanContext& context, const std::string& path, ViewerState& state,
            const std::function<bool(std::string_view)>& given = nullptr);
  // No volume any more (same condition as load); forgets a load under way.
  void unload(ViewerState& state);

  // Starts reading `path` on another thread; poll() shows it once read.
  // A load already under way is forgotten (its result is dropped).
  void startLoad(const std::string& path);
  bool loading() const { return pending_.valid(); }
  const std::string& loadingPath() const { return pending_path_; }
  // When the read started by startLoad is done: uploads it as load() does
  // (call between frames) and returns true; throws load()'s Error when it
  // could not be read. False while it is still being read, or none is.
  bool poll(const gpu::VulkanContext& context, ViewerState& state);

  // The volume for GpuScene::anatomy; null when none.
  const GpuAnatomy* gpu() const { return volume_ && !volume_->empty() ? volume_.get() : nullptr; }
  // The camera with its depth range widened to the whole volume.
  Camera inView(const Camera& camera) const;

 private:
  // Uploads a volume read: the second half of load().
  void show(const gpu::VulkanContext& context, const std::string& path, const NiftiVolume& volume, ViewerState& state,
            const std::function<bool(std::string_view)>& given);

  std::unique_ptr<GpuAnatomy> volume_;
  std::future<NiftiVolume> pending_;
  std::string pending_path_;
};

}  // namespace fibscope
