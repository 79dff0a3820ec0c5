// Compression on the fly: a tractogram in memory (read from .tck, .trk,
// .trx, .vtk or the phantom) encoded to fiblets in memory and uploaded, so
// `fibscope render FILE.tck` needs no .fbl on disk.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "codec/codec_params.h"
#include "core/progress.h"
#include "core/tractogram.h"
#include "gpu/vulkan_context.h"
#include "io/reader.h"
#include "render/camera.h"
#include "render/gpu/dataset.h"

namespace fibscope {

struct TractogramUpload {
  GpuDataset dataset;
  CodecParams params;       // as estimated from the data (chooseCodecParams)
  double encode_seconds = 0;
  double upload_seconds = 0;
};

// Encodes `tractogram` on every core with parameters estimated from it
// (N = 60; the same records as encodeTractogram) and uploads the result. `name` stands
// for the file in messages. Throws Error as chooseCodecParams,
// encodeTractogram and GpuDataset::upload do (e.g. a dataset that does not
// fit on the device).
TractogramUpload uploadTractogram(const gpu::VulkanContext& context, const Tractogram& tractogram,
                                  const std::string& name, Progress* progress = nullptr);

// The same from a reader instead of a tractogram in memory: two passes over
// the input (as `fibscope compress` does), the first estimating the codec
// parameters, the box and a sample of the points, the second encoding
// chunks on every core as they are read, so the points are never all in
// memory (a 250 MB .tck is read twice in less time than it is copied once
// into one Tractogram). `open` opens the input afresh for each pass.
struct StreamedUpload {
  TractogramUpload upload;
  Bounds bounds;                // of every point
  std::vector<Vec3d> sample;    // about 4096 to 8192 of the points (snugCamera)
  uint64_t streamlines = 0, points = 0, segments = 0;
  double read_seconds = 0;      // the first pass (reading and estimating)
  std::vector<std::string> warnings;  // the reader's
};
StreamedUpload uploadStreamed(const gpu::VulkanContext& context,
                              const std::function<std::unique_ptr<TractogramReader>()>& open,
                              const std::string& name, Progress* progress = nullptr);

// The device is needed only once the input is read and encoded: a caller
// that creates it meanwhile on another thread (`render`: instance, device
// and pipelines are made during the first pass over the file) passes a
// function that waits for it; it is called right before each upload.
using ContextSource = std::function<const gpu::VulkanContext&()>;
StreamedUpload uploadStreamed(const ContextSource& context,
                              const std::function<std::unique_ptr<TractogramReader>()>& open,
                              const std::string& name, Progress* progress = nullptr);

// Arc length of every streamline, mm.
std::vector<float> streamlineLengths(const Tractogram& tractogram);

}  // namespace fibscope
