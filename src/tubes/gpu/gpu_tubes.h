// The tubes buffer on the device (shared/tubes.h: node and segment
// records of a TubeModel) and the compute ray caster's frame stage.
#pragma once

#include <cstdint>
#include <string_view>

#include "gpu/buffer.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/frame_stage.h"
#include "tubes/tube_model.h"

namespace fibscope {

struct GpuTubes {
  gpu::Buffer nodes;     // TubeNode per node
  gpu::Buffer segments;  // TubeSegment per segment
  uint32_t node_count = 0;
  uint32_t segment_count = 0;
  uint32_t subSegmentCount() const { return 2 * segment_count; }
};

// Uploads the model's records (device-local). A model without segments
// gives empty buffers (nothing to draw). Throws Error when memory runs out
// or the model holds 2^31 segments or more (sub-segment indices are 32-bit).
GpuTubes uploadTubes(const gpu::VulkanContext& context, const TubeModel& model);
void destroyTubes(const gpu::VulkanContext& context, GpuTubes& tubes);

// The compute ray caster's tile lists (shared/tubes.h): the buffer grows
// to a frame's total for the next frame up to `max_list_bytes` (at most
// 2^28 items); tiles whose lists do not fit test every sub-segment.
struct TubeRaycastOptions {
  uint64_t max_list_bytes = uint64_t(512) << 20;
};

// Surfaces: "tube bin count", "tube bin offsets", "tube bin fill" and
// "tube raycast", the compute ray casting of `tubes` into the surface
// target (tube_bin_*.comp, tube_raycast.comp); runs in frames where `tubes`
// is not null and has segments. `tubes` is read at every frame and must
// outlive the renderer.
FrameStageFactory tubeRaycastStage(const GpuTubes* tubes, TubeRaycastOptions options = {});

// The tube methods name their timed passes "tube ..." (render's and
// bench's tube time is their sum).
inline bool isTubePass(std::string_view name) { return name.starts_with("tube "); }

// Surfaces: the tubes by the frame's RenderSettings::tube_method
// (tube_stage.cpp: compute, raycast or tess), switchable frame to frame.
FrameStageFactory tubeStage(const GpuTubes* tubes);

// `stages` with tubeStage(tubes) inserted before the surface merge (at the
// end when the list has none).
FrameStageList withTubeStage(FrameStageList stages, const GpuTubes* tubes);

}  // namespace fibscope
