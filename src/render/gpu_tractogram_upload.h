// Compression on the fly: a tractogram in memory (read from .tck, .trk,
// .trx, .vtk or the phantom) encoded to fiblets in memory and uploaded, so
// `fibscope render FILE.tck` needs no .fbl on disk.
#pragma once

#include <string>

#include "codec/codec_params.h"
#include "core/progress.h"
#include "core/tractogram.h"
#include "gpu/vulkan_context.h"
#include "render/gpu_dataset.h"

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

// Arc length of every streamline, mm.
std::vector<float> streamlineLengths(const Tractogram& tractogram);

}  // namespace fibscope
