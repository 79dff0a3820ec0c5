// A small model for the bundling tests: two families of wavy fibers (along
// x, and crossing them along y), each fiber 2 mm steps, deterministic for a
// seed, in a box of about 80 x 80 x 30 mm.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "core/tractogram.h"

namespace fibscope::test {

inline Tractogram wavyBundlingModel(size_t fibers, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::uniform_int_distribution<int> len(20, 41);
  Tractogram t;
  for (size_t f = 0; f < fibers; ++f) {
    const bool along_x = f % 3 != 2;
    const int n = len(rng);
    const float a = 12 * u(rng), b = 12 * u(rng), phase = 3 * u(rng), start = -40 + 10 * (u(rng) + 1) / 2;
    std::vector<float> xyz;
    for (int i = 0; i < n; ++i) {
      const float s = start + 2.0f * float(i);
      const float wave = 3 * std::sin(0.08f * s + phase);
      const float across = a + wave, up = b + 0.5f * wave;
      if (along_x) {
        xyz.insert(xyz.end(), {s, across, up});
      } else {
        xyz.insert(xyz.end(), {across, s, up});
      }
    }
    t.addStreamline(xyz.data(), size_t(n));
  }
  return t;
}

}  // namespace fibscope::test
