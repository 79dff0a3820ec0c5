#include "render/gpu/frame_stages.h"

namespace fibscope {

FrameStageList shadingStages() { return {makeTilesStage, makeSsaoStage, makeShadeStage, makePostStage, makeFxaaStage}; }

FrameStageList standardFrameStages() {
  FrameStageList list = {
      makeSetupStage,
      // Before any geometry: the depths the rasters and the cull read.
      makeCutMeshStage,
      // Geometry: the lines' G-buffer (one of them runs).
      makeFibletStage,
      makeRawComputeStage,
      makeLinesStage,
      makeGeometryStage,
      makeTessellationStage,
      makeMeshStage,
      makeMeshSerialStage,
      // Surfaces into the surface target, then merged by depth.
      makeSphereStage,
      makeAnatomyStage,
      makeSurfaceMergeStage,
  };
  for (FrameStageFactory& f : shadingStages()) list.push_back(std::move(f));
  list.push_back(makeOrientationStage);  // over the final image
  return list;
}

}  // namespace fibscope
