// What `fibscope render` and `fibscope bench` draw: a tractogram file (any
// readable format; .fbl uploaded as stored, anything else compressed on the
// fly in memory) or, with no file, the built-in phantom, uploaded to the
// GPU with the camera box.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/tractogram.h"
#include "gpu/vulkan_context.h"
#include "render/camera.h"
#include "render/gpu/dataset.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "select/scalar_range.h"

namespace fibscope {

struct SceneOptions {
  std::string path;                      // empty: the built-in phantom
  uint64_t phantom_streamlines = 10000;  // built-in phantom size
  bool upload_raw = false;               // also upload the raw vertices (the baselines draw them)
  bool progress = true;                  // progress bars on a terminal
  // The fiber filter's scalar ranges: their per-streamline values are read
  // too (LoadedScene::fiber_scalars).
  std::vector<ScalarRange> fiber_scalars;
};

struct LoadedScene {
  std::string name;      // the file, or "phantom"
  GpuDataset fiblets;
  GpuRawTractogram raw;  // with upload_raw (for .fbl: the decoded points); else empty
  bool has_raw = false;
  Bounds bounds;
  std::vector<Vec3d> sample;  // ~4096 of the points, to frame the view (snugCamera)
  uint64_t streamlines = 0, segments = 0;
  // Per SceneOptions::fiber_scalars range, its value for every fiber (the
  // scene's fibers are the file's streamlines, in order).
  std::vector<std::vector<float>> fiber_scalars;
  float step_size_mm = NAN;  // the header's (select/fiber_filter.h: headerStepSize), NaN when it states none
  double read_seconds = 0, encode_seconds = 0, upload_seconds = 0;

  // What a frame of this scene draws.
  GpuScene gpuScene() const { return GpuScene{&fiblets, has_raw ? &raw : nullptr}; }
};

// Reads, encodes and uploads. Throws Error naming the file for unreadable or
// malformed input, for a scalar range whose array the file lacks (before
// anything else is read), and for a dataset that does not fit on the device.
LoadedScene loadScene(const gpu::VulkanContext& context, const SceneOptions& options);
// The same with the device made meanwhile (see ContextSource in
// render/gpu/tractogram_upload.h): `context` is called when an upload
// starts, after the reading and encoding.
LoadedScene loadScene(const ContextSource& context, const SceneOptions& options);

}  // namespace fibscope
