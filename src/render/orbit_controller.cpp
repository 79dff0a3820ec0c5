#include "render/orbit_controller.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.h"

namespace fibscope {
namespace {

Vec3d add(Vec3d a, Vec3d b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3d sub(Vec3d a, Vec3d b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3d scale(Vec3d a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(Vec3d a, Vec3d b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double length(Vec3d a) { return std::sqrt(dot(a, a)); }
Vec3d cross(Vec3d a, Vec3d b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3d unit(Vec3d a) { return scale(a, 1.0 / length(a)); }
double radians(double deg) { return deg * std::numbers::pi / 180.0; }

std::array<Vec3d, 8> cornersOf(const Bounds& b) {
  std::array<Vec3d, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[i] = {(i & 1) ? b.max[0] : b.min[0], (i & 2) ? b.max[1] : b.min[1], (i & 4) ? b.max[2] : b.min[2]};
  return corners;
}
// Radius of the box's bounding sphere, at least 1 mm (fitCamera's rule).
double radiusOf(const Bounds& b) { return std::max(length(sub(b.max, b.min)) / 2, 1.0); }

// The orientation of a camera whose eye lies on `back` from the target with
// `up` (projected orthogonal to back), as camera.h's viewMatrix builds it.
Quat orientationOf(Vec3d back, Vec3d up) {
  const Vec3d z = unit(back);
  const Vec3d x = unit(cross(up, z));
  const Vec3d y = cross(z, x);
  return quatFromAxes(x, y, z);
}

// Angle between two orientations, radians in [0, pi].
double angleBetween(const Quat& a, const Quat& b) {
  const double d = std::fabs(a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z);
  return 2 * std::acos(std::min(d, 1.0));
}

}  // namespace

Quat quatNormalize(const Quat& q) {
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!(n > 0) || !std::isfinite(n)) return Quat{};
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

Quat quatMultiply(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,  //
          a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,  //
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,  //
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

Vec3d quatRotate(const Quat& q, const Vec3d& v) {
  // v + 2 w (u x v) + 2 u x (u x v), u the vector part.
  const Vec3d u = {q.x, q.y, q.z};
  const Vec3d t = scale(cross(u, v), 2);
  return add(add(v, scale(t, q.w)), cross(u, t));
}

Quat quatAxisAngle(const Vec3d& unit_axis, double radians) {
  const double s = std::sin(radians / 2);
  return {std::cos(radians / 2), unit_axis[0] * s, unit_axis[1] * s, unit_axis[2] * s};
}

Quat quatSlerp(const Quat& a, const Quat& b_in, double t) {
  Quat b = b_in;
  double d = a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z;
  if (d < 0) {  // q and -q are the same rotation: take the short way
    b = {-b.w, -b.x, -b.y, -b.z};
    d = -d;
  }
  double wa, wb;
  if (d > 1 - 1e-12) {  // nearly equal: the chord is the arc
    wa = 1 - t;
    wb = t;
  } else {
    const double theta = std::acos(d);
    const double s = std::sin(theta);
    wa = std::sin((1 - t) * theta) / s;
    wb = std::sin(t * theta) / s;
  }
  return quatNormalize({wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z});
}

Quat quatFromAxes(const Vec3d& x, const Vec3d& y, const Vec3d& z) {
  // Rotation matrix with columns x, y, z (Shepperd's method: pivot on the
  // largest of w, x, y, z for accuracy).
  const double m00 = x[0], m10 = x[1], m20 = x[2];
  const double m01 = y[0], m11 = y[1], m21 = y[2];
  const double m02 = z[0], m12 = z[1], m22 = z[2];
  const double trace = m00 + m11 + m22;
  Quat q;
  if (trace > 0) {
    const double s = 2 * std::sqrt(1 + trace);
    q = {s / 4, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s};
  } else if (m00 > m11 && m00 > m22) {
    const double s = 2 * std::sqrt(1 + m00 - m11 - m22);
    q = {(m21 - m12) / s, s / 4, (m01 + m10) / s, (m02 + m20) / s};
  } else if (m11 > m22) {
    const double s = 2 * std::sqrt(1 + m11 - m00 - m22);
    q = {(m02 - m20) / s, (m01 + m10) / s, s / 4, (m12 + m21) / s};
  } else {
    const double s = 2 * std::sqrt(1 + m22 - m00 - m11);
    q = {(m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, s / 4};
  }
  return quatNormalize(q);
}

OrbitController::OrbitController() {
  // A unit box at the origin until frame() gives the model's.
  bounds_ = {{-50, -50, -50}, {50, 50, 50}};
  goal_ = shown_ = defaultState();
}

OrbitController::State OrbitController::defaultState() const {
  const uint32_t w = std::max<uint32_t>(viewport_width_, 1), h = std::max<uint32_t>(viewport_height_, 1);
  auto make = [&](double factor) {
    return orbitCamera(bounds_, kDefaultAzimuthDeg, kDefaultElevationDeg, w, h, factor, fov_y_deg_);
  };
  Camera fitted;
  if (sample_.empty()) {
    const std::array<Vec3d, 8> corners = cornersOf(bounds_);
    fitted = snugCamera(corners, make);
  } else {
    fitted = snugCamera(sample_, make);
  }
  State state;
  state.target = fitted.target;
  const Vec3d back = sub(fitted.eye, fitted.target);
  state.distance = length(back);
  state.orientation = orientationOf(back, fitted.up);
  return state;
}

void OrbitController::frame(const Bounds& bounds, std::span<const Vec3d> sample) {
  Bounds b = bounds;
  for (int k = 0; k < 3; ++k)
    if (!(b.min[k] <= b.max[k]) || !std::isfinite(b.min[k]) || !std::isfinite(b.max[k]))
      b = Bounds{};  // an empty or broken box: a point at the origin (fitCamera gives it 1 mm)
  bounds_ = b;
  sample_.assign(sample.begin(), sample.end());
  goal_ = shown_ = defaultState();
  fitted_distance_ = goal_.distance;
}

void OrbitController::reset() {
  goal_ = defaultState();
  fitted_distance_ = goal_.distance;
}

double OrbitController::clampDistance(double distance) const {
  return std::clamp(distance, fitted_distance_ * kMinDistanceFactor, fitted_distance_ * kMaxDistanceFactor);
}

void OrbitController::rotate(double dx_px, double dy_px) {
  if (!std::isfinite(dx_px) || !std::isfinite(dy_px)) return;
  // Turning the camera frame about its own up axis by a positive angle moves
  // the eye towards the image's right, so the scene moves left: negate to
  // make the scene follow the cursor. Likewise about the right axis a
  // positive angle moves the eye down; dragging down (dy > 0) must move it up.
  const Quat turn = quatMultiply(quatAxisAngle({0, 1, 0}, -radians(dx_px * kDegreesPerPixel)),
                                 quatAxisAngle({1, 0, 0}, -radians(dy_px * kDegreesPerPixel)));
  // Local axes: right-multiply (the rotation is expressed in the camera frame).
  goal_.orientation = quatNormalize(quatMultiply(goal_.orientation, turn));
}

void OrbitController::pan(double dx_px, double dy_px) {
  if (!std::isfinite(dx_px) || !std::isfinite(dy_px)) return;
  // At the target's depth d the image spans 2 d tan(fov / 2) mm vertically
  // over `height` pixels (square pixels: the same scale horizontally). Moving
  // the eye and target by -delta moves every point of that plane by +delta
  // in view space at the same depth, i.e. by delta / mm_per_px pixels.
  const double mm_per_px =
      2 * goal_.distance * std::tan(radians(fov_y_deg_) / 2) / double(std::max<uint32_t>(viewport_height_, 1));
  const Vec3d right = quatRotate(goal_.orientation, {1, 0, 0});
  const Vec3d up = quatRotate(goal_.orientation, {0, 1, 0});
  // Window y points down: dragging down must move the point down, so the
  // target moves up.
  Vec3d target = add(goal_.target, add(scale(right, -dx_px * mm_per_px), scale(up, dy_px * mm_per_px)));
  // Keep the target within the box grown by its diagonal either side, so the
  // model cannot be lost far off screen.
  const double slack = 2 * radiusOf(bounds_);
  for (int k = 0; k < 3; ++k) target[k] = std::clamp(target[k], bounds_.min[k] - slack, bounds_.max[k] + slack);
  goal_.target = target;
}

void OrbitController::dolly(double wheel_steps) {
  if (!std::isfinite(wheel_steps)) return;
  goal_.distance = clampDistance(goal_.distance * std::pow(kDollyPerStep, -wheel_steps));
}

void OrbitController::setStandardView(StandardView view) {
  Vec3d back{}, up{};
  switch (view) {  // camera.h's standardView
    case StandardView::Sagittal: back = {1, 0, 0}, up = {0, 0, 1}; break;
    case StandardView::Coronal: back = {0, 1, 0}, up = {0, 0, 1}; break;
    case StandardView::Axial: back = {0, 0, 1}, up = {0, 1, 0}; break;
  }
  goal_.orientation = orientationOf(back, up);
}

void OrbitController::lookAt(const Vec3d& point) {
  if (std::isfinite(point[0]) && std::isfinite(point[1]) && std::isfinite(point[2])) goal_.target = point;
}

void OrbitController::setFovY(double degrees) {
  if (!std::isfinite(degrees)) return;
  fov_y_deg_ = std::clamp(degrees, kMinFovDeg, kMaxFovDeg);
}

void OrbitController::update(double dt_seconds) {
  if (!(dt_seconds > 0) || !std::isfinite(dt_seconds)) return;
  // The remaining difference decays by `keep`; since keep(a) keep(b) =
  // keep(a + b) and each quantity moves along a fixed path towards the goal
  // (a line, a log line, a great circle), split steps compose exactly.
  const double keep = std::exp(-dt_seconds / kTimeConstantSeconds);
  for (int k = 0; k < 3; ++k) shown_.target[k] = goal_.target[k] + (shown_.target[k] - goal_.target[k]) * keep;
  shown_.distance = goal_.distance * std::exp((std::log(shown_.distance) - std::log(goal_.distance)) * keep);
  shown_.orientation = quatSlerp(shown_.orientation, goal_.orientation, 1 - keep);
  if (!animating()) shown_ = goal_;
}

bool OrbitController::animating() const {
  // Below these the motion is far under a pixel: 1e-6 of the distance, a
  // microradian.
  const double eps = 1e-6 * goal_.distance;
  return length(sub(shown_.target, goal_.target)) > eps || std::fabs(shown_.distance - goal_.distance) > eps ||
         angleBetween(shown_.orientation, goal_.orientation) > 1e-6;
}

void OrbitController::finishAnimation() { shown_ = goal_; }

void OrbitController::setViewport(uint32_t width, uint32_t height) {
  if (width == 0 || height == 0) return;
  viewport_width_ = width;
  viewport_height_ = height;
}

Camera OrbitController::makeCamera(const State& state, uint32_t width, uint32_t height) const {
  const Vec3d back = quatRotate(state.orientation, {0, 0, 1});
  Camera camera;
  camera.target = state.target;
  camera.eye = add(state.target, scale(back, state.distance));
  camera.up = quatRotate(state.orientation, {0, 1, 0});
  camera.fov_y_deg = fov_y_deg_;
  camera.width = std::max<uint32_t>(width, 1);
  camera.height = std::max<uint32_t>(height, 1);
  // Near and far from the box corners' depths along the view direction with
  // a 1 % margin of the bounding radius; the box is convex, so its depth
  // range is its corners'. Near keeps a floor of 1e-4 of the distance when
  // the eye is inside (or right at) the box: the part behind it is clipped
  // anyway, and a tiny positive near keeps the matrices valid.
  const Vec3d forward = scale(back, -1);
  double min_depth = std::numeric_limits<double>::infinity(), max_depth = -min_depth;
  for (const Vec3d& corner : cornersOf(bounds_)) {
    const double depth = dot(sub(corner, camera.eye), forward);
    min_depth = std::min(min_depth, depth);
    max_depth = std::max(max_depth, depth);
  }
  const double margin = 0.01 * radiusOf(bounds_);
  camera.near_mm = std::max(min_depth - margin, 1e-4 * state.distance);
  camera.far_mm = std::max(max_depth + margin, camera.near_mm + state.distance);
  return camera;
}

Camera OrbitController::camera(uint32_t width, uint32_t height) const {
  if (width > 0 && height > 0) {
    viewport_width_ = width;
    viewport_height_ = height;
  }
  return makeCamera(shown_, width, height);
}

Camera OrbitController::goalCamera(uint32_t width, uint32_t height) const {
  return makeCamera(goal_, width, height);
}

}  // namespace fibscope
