#include "tubes/gpu/gpu_tubes.h"

#include <string>

#include "core/error.h"
#include "render/gpu/frame_stages.h"

namespace fibscope {

GpuTubes uploadTubes(const gpu::VulkanContext& context, const TubeModel& model) {
  if (model.segments.size() >= (size_t(1) << 31))
    throw Error("tubes: " + std::to_string(model.segments.size()) +
                " segments is more than the 2^31 - 1 one frame draws");
  GpuTubes tubes;
  if (model.segments.empty()) return tubes;
  try {
    const size_t node_bytes = model.nodes.size() * sizeof(model.nodes[0]);
    const size_t segment_bytes = model.segments.size() * sizeof(model.segments[0]);
    tubes.nodes = gpu::createBuffer(context, node_bytes, gpu::MemoryUse::DeviceLocal);
    tubes.segments = gpu::createBuffer(context, segment_bytes, gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context, tubes.nodes, model.nodes.data(), node_bytes);
    gpu::uploadToBuffer(context, tubes.segments, model.segments.data(), segment_bytes);
  } catch (...) {
    destroyTubes(context, tubes);
    throw;
  }
  tubes.node_count = uint32_t(model.nodes.size());
  tubes.segment_count = uint32_t(model.segments.size());
  return tubes;
}

void destroyTubes(const gpu::VulkanContext& context, GpuTubes& tubes) {
  gpu::destroyBuffer(context, tubes.segments);
  gpu::destroyBuffer(context, tubes.nodes);
  tubes.node_count = tubes.segment_count = 0;
}

FrameStageList withTubeStage(FrameStageList stages, const GpuTubes* tubes) {
  using Factory = std::unique_ptr<FrameStage> (*)(const gpu::VulkanContext&);
  auto at = stages.begin();
  for (; at != stages.end(); ++at) {
    const Factory* f = at->target<Factory>();
    if (f && *f == &makeSurfaceMergeStage) break;
  }
  stages.insert(at, tubeStage(tubes));
  return stages;
}

}  // namespace fibscope
