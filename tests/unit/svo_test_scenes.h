// Scenes for the SVO tests: a dense bundle of straight-ish fibers closer
// together than their diameter (so many more than 4 segments share a
// voxel: the seed's 4-nearest limit would lose tubes there), crossed by a
// bent fiber, plus one-point fibers (spheres) and a fiber with a repeated
// point (a zero-length step).
#pragma once

#include <cmath>
#include <vector>

#include "core/tractogram.h"
#include "render/camera.h"
#include "tubes/tube_model.h"

namespace fibscope::test {

inline Tractogram denseSvoBundle(int fibers = 24) {
  Tractogram t;
  for (int f = 0; f < fibers; ++f) {
    const float a = 2.399963f * float(f);  // golden angle: a sunflower cross-section
    const float rr = 0.22f * std::sqrt(float(f));
    std::vector<float> xyz;
    for (int i = 0; i <= 10; ++i) {
      const float x = -5.0f + float(i);
      xyz.insert(xyz.end(), {x, rr * std::cos(a) + 0.3f * std::sin(0.4f * x + float(f)),
                             rr * std::sin(a) + 0.2f * std::cos(0.3f * x)});
    }
    t.addStreamline(xyz.data(), xyz.size() / 3);
  }
  {  // a fiber crossing the bundle, with a zero-length step
    std::vector<float> xyz;
    for (int i = 0; i <= 6; ++i) xyz.insert(xyz.end(), {0.5f * float(i) - 1.5f, -3.0f + float(i), 1.2f - 0.3f * float(i)});
    xyz.insert(xyz.end(), {1.5f, 3.0f, -0.6f});  // the last point repeated
    t.addStreamline(xyz.data(), xyz.size() / 3);
  }
  const float spheres[][3] = {{-3.0f, 2.5f, 0.5f}, {3.0f, -2.5f, -0.5f}};
  for (const auto& s : spheres) t.addStreamline(s, 1);
  return t;
}

inline TubeBuildOptions svoTubeOptions(float radius) {
  TubeBuildOptions o;
  o.radius.radius = radius;
  return o;
}

inline Camera svoCamera(const Tractogram& t, double dx, double dy, double dz, uint32_t w, uint32_t h) {
  return fitCamera(tractogramBounds(t), {dx, dy, dz}, {0, 0, 1}, w, h);
}

}  // namespace fibscope::test
