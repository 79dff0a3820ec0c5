#include "app/render_scene.h"

#include <chrono>
#include <cstdio>

#include "app/open_input.h"
#include "codec/fbl_file.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/gpu/tractogram_upload.h"
#include "select/fiber_filter.h"

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
  return loadScene([&]() -> const gpu::VulkanContext& { return context; }, options);
}

LoadedScene loadScene(const ContextSource& device, const SceneOptions& options) {
  LoadedScene scene;
  scene.name = options.path.empty() ? "phantom" : options.path;
  PhantomOptions phantom;
  phantom.streamlines = options.phantom_streamlines;
  if (options.path.empty()) validatePhantomOptions(phantom);
  auto open = [&]() { return options.path.empty() ? openPhantom(phantom) : openInput(options.path); };
  auto printWarnings = [](const std::vector<std::string>& warnings) {
    for (const std::string& warning : warnings) std::fprintf(stderr, "fibscope: warning: %s\n", warning.c_str());
  };
  const bool fbl = !options.path.empty() && isFblPath(options.path);
  if (!options.fiber_scalars.empty()) {
    // The arrays are checked first: a missing one is one line before any work.
    const auto reader = open();
    resolveScalarColumns(options.fiber_scalars, reader->header().per_streamline, scene.name);
  }

  if (!fbl && !options.upload_raw) {
    // The compute pipeline alone: stream the input twice (estimate, then
    // encode chunks as they are read); the points are never all in memory.
    StreamedUpload streamed = uploadStreamed(device, open, scene.name);
    printWarnings(streamed.warnings);
    if (streamed.streamlines == 0) throw Error(scene.name + ": no streamlines to render");
    scene.fiblets = std::move(streamed.upload.dataset);
    scene.bounds = streamed.bounds;
    scene.sample = std::move(streamed.sample);
    scene.streamlines = streamed.streamlines;
    scene.segments = streamed.segments;
    scene.read_seconds = streamed.read_seconds;
    scene.encode_seconds = streamed.upload.encode_seconds;
    scene.upload_seconds = streamed.upload.upload_seconds;
    scene.step_size_mm = headerStepSize(open()->header());
    // A third pass for the values alone (the stream kept no data arrays).
    if (!options.fiber_scalars.empty()) scene.fiber_scalars = readScalarValues(*open(), options.fiber_scalars);
    return scene;
  }

  auto t0 = Clock::now();
  std::unique_ptr<TractogramReader> reader = open();
  Tractogram points = readAllStreamlines(*reader);
  printWarnings(reader->warnings());
  scene.step_size_mm = headerStepSize(reader->header());
  if (points.streamlineCount() == 0) throw Error(scene.name + ": no streamlines to render");
  scene.read_seconds = secondsSince(t0);
  scene.bounds = tractogramBounds(points);
  scene.sample = samplePoints(points);
  scene.streamlines = points.streamlineCount();
  scene.segments = segmentCount(points);
  if (!options.fiber_scalars.empty()) scene.fiber_scalars = scalarValues(points, options.fiber_scalars, scene.name);

  if (fbl) {
    // Already fiblets: upload the records as stored (the decode above gave
    // the box and, for the baselines, the points).
    const FblFile file = FblFile::open(options.path);
    const gpu::VulkanContext& context = device();
    t0 = Clock::now();
    scene.fiblets = GpuDataset::upload(context, file);
    scene.upload_seconds = secondsSince(t0);
  } else {
    TractogramUpload upload = uploadTractogram(device(), points, scene.name);
    scene.fiblets = std::move(upload.dataset);
    scene.encode_seconds = upload.encode_seconds;
    scene.upload_seconds = upload.upload_seconds;
  }
  if (options.upload_raw) {
    t0 = Clock::now();
    scene.raw = GpuRawTractogram::upload(device(), points, scene.name);
    scene.has_raw = true;
    scene.upload_seconds += secondsSince(t0);
  }
  return scene;
}

}  // namespace fibscope
