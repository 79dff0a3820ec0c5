#include "render/clip_planes.h"

#include <cmath>
#include <string>

#include "core/error.h"
#include "shared/camera.h"

namespace fibscope {
namespace {

bool finite(const PlaneEq& q) {
  for (double v : q)
    if (!std::isfinite(v)) return false;
  return true;
}

// (n, d) with n unit, or an Error.
PlaneEq normalised(const PlaneEq& q, const char* what) {
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  if (!finite(q) || !(len > 0)) throw Error(std::string(what) + ": a plane needs a finite, non-zero normal");
  return {q[0] / len, q[1] / len, q[2] / len, q[3] / len};
}

}  // namespace

PlaneEq planeThrough(const std::array<double, 3>& point, const std::array<double, 3>& normal) {
  for (double v : point)
    if (!std::isfinite(v)) throw Error("clip plane: the point must be finite");
  const PlaneEq n = normalised({normal[0], normal[1], normal[2], 0}, "clip plane");
  return {n[0], n[1], n[2], -(n[0] * point[0] + n[1] * point[1] + n[2] * point[2])};
}

std::vector<PlaneEq> frameClipPlanes(const RenderSettings& s, const Camera& camera) {
  if (s.clip_planes.size() > shader::kMaxClipPlanes)
    throw Error("clip planes: at most " + std::to_string(shader::kMaxClipPlanes) + ", got " +
                std::to_string(s.clip_planes.size()));
  std::vector<PlaneEq> planes;
  for (const PlaneEq& q : s.clip_planes) planes.push_back(normalised(q, "clip plane"));
  if (!(s.slab_mm >= 0) || !std::isfinite(s.slab_mm)) throw Error("slab: expected a thickness >= 0 mm");
  if (s.slab_mm > 0) {
    PlaneEq centre;
    if (s.slab_plane) {
      centre = normalised(*s.slab_plane, "slab");
    } else {
      const std::array<double, 3> towards_eye = {camera.eye[0] - camera.target[0], camera.eye[1] - camera.target[1],
                                                 camera.eye[2] - camera.target[2]};
      centre = planeThrough(camera.target, towards_eye);
    }
    const double half = 0.5 * double(s.slab_mm);
    planes.push_back({centre[0], centre[1], centre[2], centre[3] + half});      // n.p + d >= -half
    planes.push_back({-centre[0], -centre[1], -centre[2], half - centre[3]});  // n.p + d <= half
  }
  return planes;
}

bool keptByPlanes(const std::vector<PlaneEq>& planes, const std::array<double, 3>& p) {
  for (const PlaneEq& q : planes)
    if (q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] < 0) return false;
  return true;
}

}  // namespace fibscope
