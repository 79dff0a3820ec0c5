// Scenes for the SVO tests: a dense bundle of straight-ish fibers closer
// together than their diameter (so many more than 4 segments share a
// voxel: the seed's 4-nearest limit would lose tubes there), crossed by a
// bent fiber, plus one-point fibers (spheres) and a fiber with a repeated
// point (a zero-length step).
#pragma once

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

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

// Curved tubes' scene: arcs sampled coarsely (25 degrees a step, so the
// Hermite segments bow visibly away from their chords), stacked closer
// than a diameter where they run side by side in z and crossed by one
// more arc, and a one-point fiber (a sphere).
inline Tractogram curvedSvoBundle() {
  Tractogram t;
  for (int f = 0; f < 5; ++f) {
    std::vector<float> xyz;
    const float r = 3.0f + 0.45f * float(f);
    for (int i = 0; i <= 8; ++i) {
      const float a = 0.4363323f * float(i);
      xyz.insert(xyz.end(), {r * std::cos(a), r * std::sin(a), 0.5f * float(f % 2) + 0.1f * float(i)});
    }
    t.addStreamline(xyz.data(), xyz.size() / 3);
  }
  {
    std::vector<float> xyz;
    for (int i = 0; i <= 6; ++i) {
      const float a = -0.6f + 0.4f * float(i);
      xyz.insert(xyz.end(), {4.0f + 2.5f * std::sin(a), -1.0f + 1.2f * float(i), 1.5f * std::cos(a) - 0.5f});
    }
    t.addStreamline(xyz.data(), xyz.size() / 3);
  }
  const float sphere[3] = {-2.0f, 1.0f, 0.5f};
  t.addStreamline(sphere, 1);
  return t;
}

// Each curved segment of `model` as `n` straight capsules between points
// of its Hermite centre line (the reference of the curved tubes): nodes
// copied from the segment's first node with the centre, the radius (the
// segment's mean, as svoCurve) and the position along the fiber replaced.
inline TubeModel subdivideCurvedTubes(const TubeModel& model, int n) {
  TubeModel out;
  for (const shader::TubeSegment& s : model.segments) {
    const shader::TubeNode& na = model.nodes[s.node];
    const shader::TubeNode& nb = model.nodes[s.node + 1];
    const float r = 0.5f * (na.position_radius.w + nb.position_radius.w);
    const uint32_t first = uint32_t(out.nodes.size());
    for (int k = 0; k <= n; ++k) {
      const float u = float(k) / float(n);
      const glm::vec3 p = tubeSegmentPoint(model, s, u);
      shader::TubeNode node = na;
      node.position_radius = {p.x, p.y, p.z, r};
      node.point = (1.0f - u) * na.point + u * nb.point;
      out.nodes.push_back(node);
    }
    for (int k = 0; k < n; ++k) {
      shader::TubeSegment sub = s;
      sub.node = first + uint32_t(k);
      const shader::vec4 a = out.nodes[sub.node].position_radius, b = out.nodes[sub.node + 1].position_radius;
      sub.chord = glm::length(glm::vec3(b.x - a.x, b.y - a.y, b.z - a.z));
      out.segments.push_back(sub);
    }
  }
  return out;
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
