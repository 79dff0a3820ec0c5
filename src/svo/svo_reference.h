// CPU references of the SVO ray tracing: the brute-force frame (every
// pixel's eye ray against every capsule of the model, in double), in the
// same image layout as the spline tubes' reference (tubes/tube_intersect.h).
#pragma once

#include "render/camera.h"
#include "tubes/tube_intersect.h"
#include "tubes/tube_model.h"

namespace fibscope {

// Nearest hit per pixel over all capsules (svoCapsule of each segment);
// ties: the smaller segment index. Cost O(pixels * segments): for tests.
TubeReferenceImage renderBruteForceCapsules(const TubeModel& model, const Camera& camera);

}  // namespace fibscope
