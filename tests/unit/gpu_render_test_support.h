// Helpers shared by the renderer's GPU tests: the test phantom, a G-buffer's
// coverage mask, and the CPU mirror of glsl/tangent.glsl's unpackTangent.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "core/tractogram.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "tubes/tube_model.h"

namespace fibscope::test {

// A brain-like phantom at 0.1 mm steps, generated on one thread
// (deterministic for the seed).
// Streamlines of the given point counts along x: point k of the whole
// tractogram at (k, 0.5 * its index in the streamline, -1). Empty and
// one-point streamlines included, for tests of tables and chunks.
inline Tractogram lineTractogram(std::initializer_list<size_t> lengths) {
  Tractogram t;
  std::vector<float> xyz;
  for (size_t n : lengths) {
    xyz.clear();
    for (size_t i = 0; i < n; ++i) {
      xyz.push_back(float(t.pointCount() + i));
      xyz.push_back(0.5f * float(i));
      xyz.push_back(-1.0f);
    }
    t.addStreamline(xyz.data(), n);
  }
  return t;
}

// The built-in phantom's first fibers at 0.1 mm (one thread): the default,
// whole-brain mix, or with `named_bundles` the named bundles alone, thin and
// apart (applyNamedBundlesPhantomMix), for tests whose views and cuts were
// placed on that layout.
inline Tractogram renderPhantom(uint64_t streamlines, uint64_t seed, bool named_bundles = false) {
  PhantomOptions options;
  if (named_bundles) applyNamedBundlesPhantomMix(options);
  options.streamlines = streamlines;
  options.step_mm = 0.1;
  options.seed = seed;
  options.threads = 1;
  return readAllStreamlines(*openPhantom(options));
}

// 1 where a fiber was drawn (compareCoverage's input).
inline std::vector<uint8_t> gbufferMask(const std::vector<shader::GBufferTexel>& texels) {
  std::vector<uint8_t> mask(texels.size());
  for (size_t i = 0; i < texels.size(); ++i) mask[i] = texels[i].fiber != shader::kNoFiberId ? 1 : 0;
  return mask;
}

// glsl/tangent.glsl's unpackTangent (tubes/tube_model.h's unpackUnitVector,
// the one C++ decoding of the packed G-buffer vectors).
inline std::array<float, 3> unpackTangent(uint32_t packed) {
  const glm::vec3 v = unpackUnitVector(packed);
  return {v.x, v.y, v.z};
}

}  // namespace fibscope::test
