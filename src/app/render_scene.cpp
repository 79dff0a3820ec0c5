#include "app/render_scene.h"

#include <chrono>
#include <cstdio>

#include "app/open_input.h"
#include "codec/fbl_file.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/gpu_tractogram_upload.h"

namespace fibscope {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

uint64_t segmentCount(const Tractogram& t) {
  uint64_t segments = 0;
  for (size_t s = 0; s < t.streamlineCount(); ++s) segments += t.pointsIn(s) > 1 ? t.pointsIn(s) - 1 : 0;
  return segments;
}

}  // namespace

LoadedScene loadScene(const gpu::VulkanContext& context, const SceneOptions& options) {
  LoadedScene scene;
  auto t0 = Clock::now();
  std::unique_ptr<TractogramReader> reader;
  if (options.path.empty()) {
    PhantomOptions phantom;
    phantom.streamlines = options.phantom_streamlines;
    validatePhantomOptions(phantom);
    scene.name = "phantom";
    reader = openPhantom(phantom);
  } else {
    scene.name = options.path;
    reader = openInput(options.path);
  }
  Tractogram points = readAllStreamlines(*reader);
  for (const std::string& warning : reader->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", warning.c_str());
  if (points.streamlineCount() == 0) throw Error(scene.name + ": no streamlines to render");
  scene.read_seconds = secondsSince(t0);
  scene.bounds = tractogramBounds(points);
  scene.sample = samplePoints(points);
  scene.streamlines = points.streamlineCount();
  scene.segments = segmentCount(points);

  if (!options.path.empty() && isFblPath(options.path)) {
    // Already fiblets: upload the records as stored (the decode above gave
    // the box and, for the baselines, the points).
    t0 = Clock::now();
    const FblFile file = FblFile::open(options.path);
    scene.fiblets = GpuDataset::upload(context, file);
    scene.upload_seconds = secondsSince(t0);
  } else {
    TractogramUpload upload = uploadTractogram(context, points, scene.name);
    scene.fiblets = std::move(upload.dataset);
    scene.encode_seconds = upload.encode_seconds;
    scene.upload_seconds = upload.upload_seconds;
  }
  if (options.upload_raw) {
    t0 = Clock::now();
    scene.raw = GpuRawTractogram::upload(context, points, scene.name);
    scene.has_raw = true;
    scene.upload_seconds += secondsSince(t0);
  }
  return scene;
}

}  // namespace fibscope
