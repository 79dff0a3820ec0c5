// Synthetic tubes for the ray-casting tests (CPU references and the GPU
// compute variant): a tight 90 degree turn, an S-curve of varying radius,
// and two tubes crossing at different depths; each with cameras from
// above, obliquely and close up, fitted to the tubes' bounds.
#pragma once

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/tractogram.h"
#include "render/camera.h"
#include "tubes/tube_model.h"

namespace fibscope::test {

struct TubeScene {
  std::string name;
  Tractogram tractogram;
  TubeBuildOptions options;
  float min_radius = 0, max_radius = 0;
};

inline std::vector<TubeScene> tubeScenes() {
  std::vector<TubeScene> scenes;
  {
    // Straight along x, a quarter circle of radius 1.5 mm (points 22.5
    // degrees apart), straight along y; radius 0.6 mm.
    TubeScene s{"tight 90-degree turn"};
    std::vector<float> xyz;
    for (int i = 0; i <= 4; ++i) xyz.insert(xyz.end(), {-6.0f + 1.5f * float(i), -1.5f, 0.0f});
    for (int i = 1; i <= 3; ++i) {
      const float a = float(i) * std::numbers::pi_v<float> / 8.0f;
      xyz.insert(xyz.end(), {1.5f * std::sin(a), -1.5f * std::cos(a), 0.0f});
    }
    for (int i = 0; i <= 4; ++i) xyz.insert(xyz.end(), {1.5f, 1.5f * float(i), 0.0f});
    s.tractogram.addStreamline(xyz.data(), xyz.size() / 3);
    s.options.radius.radius = 0.6f;
    s.min_radius = s.max_radius = 0.6f;
    scenes.push_back(std::move(s));
  }
  {
    // An S-curve in the x-z plane, radius 0.3 -> 1.0 mm per point.
    TubeScene s{"S-curve of varying radius"};
    std::vector<float> xyz, r;
    for (int i = 0; i <= 12; ++i) {
      const float x = -6.0f + float(i);
      xyz.insert(xyz.end(), {x, 0.0f, 2.0f * std::sin(x * 0.6f)});
      r.push_back(float(i) / 12.0f);
    }
    s.tractogram.addStreamline(xyz.data(), xyz.size() / 3);
    s.tractogram.per_point.push_back({"r", 1, "float32", r});
    s.options.radius.source = TubeRadius::Source::PerPoint;
    s.options.radius.array = "r";
    s.options.radius.radius_min = 0.3f;
    s.options.radius.radius_max = 1.0f;
    s.min_radius = 0.3f;
    s.max_radius = 1.0f;
    scenes.push_back(std::move(s));
  }
  {
    // Two tubes crossing, 1.5 mm apart in z, radius 0.5 mm.
    TubeScene s{"two crossing tubes"};
    std::vector<float> a, b;
    for (int i = 0; i <= 8; ++i) {
      const float u = -4.0f + float(i);
      a.insert(a.end(), {u, 0.3f * u, 0.75f + 0.1f * u * u * 0.1f});
      b.insert(b.end(), {0.2f * u, u, -0.75f});
    }
    s.tractogram.addStreamline(a.data(), a.size() / 3);
    s.tractogram.addStreamline(b.data(), b.size() / 3);
    s.options.radius.radius = 0.5f;
    s.min_radius = s.max_radius = 0.5f;
    scenes.push_back(std::move(s));
  }
  return scenes;
}

// From above (+z), obliquely, and close up (oblique, a third of the
// distance: part of the tubes outside the frame).
inline std::vector<Camera> tubeSceneCameras(const TubeScene& scene, uint32_t width, uint32_t height) {
  Bounds b = tractogramBounds(scene.tractogram);
  for (int k = 0; k < 3; ++k) {
    b.min[k] -= scene.max_radius;
    b.max[k] += scene.max_radius;
  }
  return {fitCamera(b, {0, 0, 1}, {0, 1, 0}, width, height), fitCamera(b, {1, -0.7, 0.6}, {0, 0, 1}, width, height),
          fitCamera(b, {0.3, 0.5, 1}, {0, 1, 0}, width, height, 0.35)};
}

// Lines along x in the plane z = 0 (13 rows 2 mm apart, points
// `line_step_mm` apart) and three wavy tubes of radius 0.8 mm along y above
// them, below them and through them, seen from +z at 80 mm by a w x h
// camera: the scene of the tests where tubes and lines occlude each other.
struct LinesAndTubesScene {
  Tractogram lines, tubes;
  TubeBuildOptions options;
  Camera camera;
};

inline LinesAndTubesScene linesAndTubesScene(float line_step_mm, uint32_t w, uint32_t h) {
  LinesAndTubesScene scene;
  const int line_points = int(std::lround(30.0f / line_step_mm));
  for (int row = 0; row <= 12; ++row) {
    std::vector<float> xyz;
    for (int i = 0; i <= line_points; ++i)
      xyz.insert(xyz.end(), {-15.0f + line_step_mm * float(i), -12.0f + 2.0f * float(row), 0.0f});
    scene.lines.addStreamline(xyz.data(), xyz.size() / 3);
  }
  for (int k = 0; k < 3; ++k) {
    std::vector<float> xyz;
    for (int i = 0; i <= 10; ++i) {
      const float y = -12.0f + 2.4f * float(i);
      const float z = k == 0 ? 1.5f : (k == 1 ? -1.5f : 0.25f * y);  // above, below, through
      xyz.insert(xyz.end(), {-9.0f + 9.0f * float(k) + std::sin(0.5f * y), y, z});
    }
    scene.tubes.addStreamline(xyz.data(), xyz.size() / 3);
  }
  scene.options.radius.radius = 0.8f;
  Camera& camera = scene.camera;
  camera.eye = {0, 0, 80};
  camera.target = {0, 0, 0};
  camera.up = {0, 1, 0};
  camera.width = w;
  camera.height = h;
  camera.near_mm = 60;
  camera.far_mm = 100;
  return scene;
}

}  // namespace fibscope::test
