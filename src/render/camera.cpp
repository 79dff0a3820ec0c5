#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.h"

namespace fibscope {
namespace {

using Mat4d = std::array<double, 16>;

glm::dvec3 vec(const Vec3d& a) { return {a[0], a[1], a[2]}; }

// Column-major both ways (glm's and camera.h's layout).
glm::dmat4 toGlm(const Mat4d& m) { return glm::make_mat4(m.data()); }
Mat4d fromGlm(const glm::dmat4& m) {
  Mat4d out{};
  const double* p = glm::value_ptr(m);
  std::copy(p, p + 16, out.begin());
  return out;
}

double radians(double deg) { return deg * std::numbers::pi / 180.0; }

Mat4 toFloat(const Mat4d& m) {
  Mat4 out{};
  for (size_t i = 0; i < 16; ++i) out[i] = static_cast<float>(m[i]);
  return out;
}

}  // namespace

void validateCamera(const Camera& camera) {
  const glm::dvec3 forward = vec(camera.target) - vec(camera.eye);
  const double forward_length = glm::length(forward);
  if (!(forward_length > 0) || !std::isfinite(forward_length))
    fail("camera", "eye and target must be distinct finite points");
  const double up_length = glm::length(vec(camera.up));
  if (!(up_length > 0) || !std::isfinite(up_length)) fail("camera", "up must be a finite non-zero vector");
  // sin of the angle between up and the view direction.
  if (glm::length(glm::cross(forward, vec(camera.up))) <= 1e-9 * forward_length * up_length)
    fail("camera", "up must not be parallel to the view direction");
  if (!(camera.fov_y_deg > 0 && camera.fov_y_deg < 180))
    fail("camera", "vertical field of view must lie in (0, 180) degrees, got " + std::to_string(camera.fov_y_deg));
  if (!(camera.near_mm > 0) || !(camera.far_mm > camera.near_mm) || !std::isfinite(camera.far_mm))
    fail("camera", "need 0 < near < far, got near " + std::to_string(camera.near_mm) + " far " +
                       std::to_string(camera.far_mm));
  if (camera.width == 0 || camera.height == 0) fail("camera", "image size must be at least 1 x 1");
}

std::array<double, 16> viewMatrixD(const Camera& camera) {
  validateCamera(camera);
  const glm::dvec3 eye = vec(camera.eye);
  const glm::dvec3 f = glm::normalize(vec(camera.target) - eye);
  const glm::dvec3 s = glm::normalize(glm::cross(f, vec(camera.up)));
  const glm::dvec3 u = glm::cross(s, f);
  // Rows: s, u, -f; translation moves the eye to the origin.
  return {s.x, u.x, -f.x, 0,  //
          s.y, u.y, -f.y, 0,  //
          s.z, u.z, -f.z, 0,  //
          -glm::dot(s, eye), -glm::dot(u, eye), glm::dot(f, eye), 1};
}

std::array<double, 16> projectionMatrixD(const Camera& camera) {
  validateCamera(camera);
  const double g = 1.0 / std::tan(radians(camera.fov_y_deg) / 2);
  const double aspect = double(camera.width) / double(camera.height);
  const double n = camera.near_mm, f = camera.far_mm;
  Mat4d m{};
  m[0] = g / aspect;
  m[5] = -g;                  // y down: view +y (up) goes to the top row, y_ndc = -1
  m[10] = f / (n - f);        // z_clip = (f z + n f) / (n - f): 0 at z = -n, w at z = -f
  m[11] = -1;                 // w_clip = -z_view
  m[14] = n * f / (n - f);
  return m;
}

std::array<double, 16> viewProjectionD(const Camera& camera) {
  return fromGlm(toGlm(projectionMatrixD(camera)) * toGlm(viewMatrixD(camera)));
}

Mat4 viewMatrix(const Camera& camera) { return toFloat(viewMatrixD(camera)); }
Mat4 projectionMatrix(const Camera& camera) { return toFloat(projectionMatrixD(camera)); }
Mat4 viewProjection(const Camera& camera) { return toFloat(viewProjectionD(camera)); }

shader::CameraBlock makeCameraBlock(const Camera& camera, float line_width_px,
                                    const std::vector<std::array<double, 4>>& clip_planes) {
  const Mat4 vp = viewProjection(camera);
  const Mat4 v = viewMatrix(camera);
  shader::CameraBlock block{};
  for (int c = 0; c < 4; ++c) {
    block.view_projection[c] = {vp[4 * c], vp[4 * c + 1], vp[4 * c + 2], vp[4 * c + 3]};
    block.view[c] = {v[4 * c], v[4 * c + 1], v[4 * c + 2], v[4 * c + 3]};
  }
  block.eye = {float(camera.eye[0]), float(camera.eye[1]), float(camera.eye[2]), 1.0f};
  block.viewport = {float(camera.width), float(camera.height), line_width_px, 0.0f};
  block.depth_range = {float(camera.near_mm), float(camera.far_mm), 0.0f, 0.0f};
  if (clip_planes.size() > shader::kMaxFrameClipPlanes)
    throw Error("camera: at most " + std::to_string(shader::kMaxFrameClipPlanes) + " clip planes");
  // A plane L keeps points P (homogeneous) with L.P >= 0; clip = M P, so
  // in clip space it is L.M^-1 c = (M^-T L).c >= 0.
  const glm::dmat4 inverse_transpose = glm::transpose(glm::inverse(toGlm(viewProjectionD(camera))));
  for (size_t i = 0; i < clip_planes.size(); ++i) {
    const auto& q = clip_planes[i];
    const glm::dvec4 c = inverse_transpose * glm::dvec4(q[0], q[1], q[2], q[3]);
    block.clip_world[i] = {float(q[0]), float(q[1]), float(q[2]), float(q[3])};
    block.clip_space[i] = {float(c.x), float(c.y), float(c.z), float(c.w)};
  }
  block.cuts = {float(clip_planes.size()), 0.0f, 0.0f, 0.0f};
  return block;
}

Bounds tractogramBounds(const Tractogram& tractogram) {
  if (tractogram.pointCount() == 0) return {};
  Bounds b;
  b.min.fill(std::numeric_limits<double>::infinity());
  b.max.fill(-std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < tractogram.pointCount(); ++i) {
    const float* p = tractogram.point(i);
    for (int k = 0; k < 3; ++k) {
      b.min[k] = std::min(b.min[k], double(p[k]));
      b.max[k] = std::max(b.max[k], double(p[k]));
    }
  }
  return b;
}

Camera fitCamera(const Bounds& bounds, Vec3d direction, Vec3d up, uint32_t width, uint32_t height,
                 double distance_factor, double fov_y_deg) {
  const double direction_length = glm::length(vec(direction));
  if (!(direction_length > 0)) fail("camera", "fit: view direction must be non-zero");
  if (!(distance_factor > 0)) fail("camera", "fit: distance factor must be positive");
  if (width == 0 || height == 0) fail("camera", "image size must be at least 1 x 1");
  if (!(fov_y_deg > 0 && fov_y_deg < 180)) fail("camera", "fit: vertical field of view must lie in (0, 180)");
  const Vec3d centre = {(bounds.min[0] + bounds.max[0]) / 2, (bounds.min[1] + bounds.max[1]) / 2,
                        (bounds.min[2] + bounds.max[2]) / 2};
  // A box of size 0 still gets a 1 mm sphere, so the matrices stay valid.
  const double radius = boundingRadius(bounds);
  const double half_fov_y = radians(fov_y_deg) / 2;
  const double half_fov_x = std::atan(std::tan(half_fov_y) * double(width) / double(height));
  // A sphere of radius r at distance d fills a cone of half-angle asin(r / d).
  const double distance = distance_factor * radius / std::sin(std::min(half_fov_x, half_fov_y));
  Camera camera;
  camera.eye = {centre[0] + direction[0] / direction_length * distance,
                centre[1] + direction[1] / direction_length * distance,
                centre[2] + direction[2] / direction_length * distance};
  camera.target = centre;
  camera.up = up;
  camera.fov_y_deg = fov_y_deg;
  camera.far_mm = distance + radius * 1.01;
  camera.near_mm = std::max(distance - radius * 1.01, distance * 1e-3);
  camera.width = width;
  camera.height = height;
  validateCamera(camera);
  return camera;
}

Camera orbitCamera(const Bounds& bounds, double azimuth_deg, double elevation_deg, uint32_t width,
                   uint32_t height, double distance_factor, double fov_y_deg) {
  const double az = radians(azimuth_deg), el = radians(elevation_deg);
  const Vec3d direction = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
  // d(direction)/d(elevation): orthogonal to the direction, +z at elevation 0.
  const Vec3d up = {-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az), std::cos(el)};
  return fitCamera(bounds, direction, up, width, height, distance_factor, fov_y_deg);
}

Camera standardView(const Bounds& bounds, StandardView view, uint32_t width, uint32_t height,
                    double distance_factor, double fov_y_deg) {
  switch (view) {
    case StandardView::Sagittal:
      return fitCamera(bounds, {1, 0, 0}, {0, 0, 1}, width, height, distance_factor, fov_y_deg);
    case StandardView::Coronal:
      return fitCamera(bounds, {0, 1, 0}, {0, 0, 1}, width, height, distance_factor, fov_y_deg);
    case StandardView::Axial:
      return fitCamera(bounds, {0, 0, 1}, {0, 1, 0}, width, height, distance_factor, fov_y_deg);
  }
  fail("camera", "unknown standard view");
}

Camera snugCamera(std::span<const Vec3d> points, const std::function<Camera(double factor)>& make, double margin) {
  auto fits = [&](const Camera& camera) {
    const std::array<double, 16> m = viewProjectionD(camera);
    for (const Vec3d& p : points) {
      double c[4];
      for (int r = 0; r < 4; ++r) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
      if (!(c[2] > 0) || !(std::fabs(c[0]) <= margin * c[3]) || !(std::fabs(c[1]) <= margin * c[3])) return false;
    }
    return true;
  };
  // The corners' extent on screen shrinks monotonically with the distance:
  // bisect the factor between a close camera that does not fit and 2 (at 1
  // the corners may still lie outside the margin).
  double lo = 0.02, hi = 2.0;
  if (!fits(make(hi))) return make(hi);
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    (fits(make(mid)) ? hi : lo) = mid;
  }
  return make(hi);
}

void PointSample::add(const Tractogram& chunk) {
  for (size_t i = 0; i < chunk.pointCount(); ++i, ++seen_) {
    if (seen_ % stride_ != 0) continue;
    const float* p = chunk.point(i);
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) continue;
    kept_.push_back({seen_, {p[0], p[1], p[2]}});
    if (kept_.size() > limit_) {
      stride_ *= 2;
      std::erase_if(kept_, [&](const auto& k) { return k.first % stride_ != 0; });
    }
  }
}

std::vector<Vec3d> PointSample::points() const {
  std::vector<Vec3d> out;
  out.reserve(kept_.size());
  for (const auto& k : kept_) out.push_back(k.second);
  return out;
}

std::vector<Vec3d> samplePoints(const Tractogram& tractogram, size_t count) {
  PointSample sample(2 * count);
  sample.add(tractogram);
  return sample.points();
}

std::array<Vec3d, 8> boundsCorners(const Bounds& bounds) {
  std::array<Vec3d, 8> corners;
  for (int c = 0; c < 8; ++c)
    for (int k = 0; k < 3; ++k) corners[size_t(c)][size_t(k)] = (c >> k) & 1 ? bounds.max[k] : bounds.min[k];
  return corners;
}

Bounds boundsUnion(const Bounds& a, const Bounds& b) {
  Bounds u;
  for (int k = 0; k < 3; ++k) u.min[k] = std::min(a.min[k], b.min[k]), u.max[k] = std::max(a.max[k], b.max[k]);
  return u;
}

double boundingRadius(const Bounds& bounds) {
  return std::max(glm::length(vec(bounds.max) - vec(bounds.min)) / 2, 1.0);
}

Camera enclosingDepthRange(Camera camera, std::span<const Vec3d> points) {
  const glm::dvec3 eye(camera.eye[0], camera.eye[1], camera.eye[2]);
  const glm::dvec3 forward =
      glm::normalize(glm::dvec3(camera.target[0], camera.target[1], camera.target[2]) - eye);
  double nearest = INFINITY, farthest = 0;
  for (const Vec3d& p : points) {
    const double d = glm::dot(glm::dvec3(p[0], p[1], p[2]) - eye, forward);
    if (!(d > 0)) continue;  // behind the eye: no near plane shows it
    nearest = std::min(nearest, d);
    farthest = std::max(farthest, d);
  }
  if (!(farthest > 0)) return camera;
  camera.far_mm = std::max(camera.far_mm, 1.01 * farthest);
  // Not nearer than a thousandth of the far plane: the depth buffer's
  // float precision near the far plane falls with far / near.
  camera.near_mm = std::min(camera.near_mm, std::max(0.99 * nearest, 1e-3 * camera.far_mm));
  return camera;
}

}  // namespace fibscope
