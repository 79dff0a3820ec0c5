#include "app/viewer/orbit_controller.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/error.h"

namespace fibscope {
namespace {

glm::dvec3 vec(const Vec3d& a) { return {a[0], a[1], a[2]}; }
Vec3d array(const glm::dvec3& a) { return {a.x, a.y, a.z}; }
double radians(double deg) { return deg * std::numbers::pi / 180.0; }

// glm::normalize, and the identity for a quaternion of no finite length.
Quat unitOrIdentity(const Quat& q) {
  const double n = glm::length(q);
  return n > 0 && std::isfinite(n) ? q / n : Quat{};
}

// The orientation of a camera whose eye lies on `back` from the target with
// `up` (projected orthogonal to back), as camera.h's viewMatrix builds it:
// the rotation whose columns are its right, up and back axes.
Quat orientationOf(const Vec3d& back, const Vec3d& up) {
  const glm::dvec3 z = glm::normalize(vec(back));
  const glm::dvec3 x = glm::normalize(glm::cross(vec(up), z));
  const glm::dvec3 y = glm::cross(z, x);
  return unitOrIdentity(glm::quat_cast(glm::dmat3(x, y, z)));
}

// Angle between two orientations, radians in [0, pi].
double angleBetween(const Quat& a, const Quat& b) {
  return 2 * std::acos(std::min(std::fabs(glm::dot(a, b)), 1.0));
}

// The camera's axis `local` (x right, y up, z back) in world space.
Vec3d axis(const Quat& q, const glm::dvec3& local) { return array(q * local); }

}  // namespace

OrbitController::OrbitController() {
  // A unit box at the origin until frame() gives the model's.
  bounds_ = fitted_bounds_ = {{-50, -50, -50}, {50, 50, 50}};
  goal_ = shown_ = defaultState();
}

OrbitController::State OrbitController::defaultState() const {
  const uint32_t w = std::max<uint32_t>(viewport_width_, 1), h = std::max<uint32_t>(viewport_height_, 1);
  auto make = [&](double factor) {
    return orbitCamera(bounds_, kDefaultAzimuthDeg, kDefaultElevationDeg, w, h, factor, fov_y_deg_);
  };
  const std::array<Vec3d, 8> corners = boundsCorners(bounds_);
  return stateOf(sample_.empty() ? snugCamera(corners, make) : snugCamera(sample_, make));
}

OrbitController::State OrbitController::fittedState(const Quat& orientation) const {
  const uint32_t w = std::max<uint32_t>(viewport_width_, 1), h = std::max<uint32_t>(viewport_height_, 1);
  const Vec3d back = axis(orientation, {0, 0, 1}), up = axis(orientation, {0, 1, 0});
  auto make = [&](double factor) { return fitCamera(bounds_, back, up, w, h, factor, fov_y_deg_); };
  const std::array<Vec3d, 8> corners = boundsCorners(bounds_);
  State state = stateOf(sample_.empty() ? snugCamera(corners, make) : snugCamera(sample_, make));
  state.orientation = orientation;  // exactly, not re-derived through the eye
  return state;
}

OrbitController::State OrbitController::stateOf(const Camera& camera) {
  State state;
  state.target = camera.target;
  const Vec3d back = array(vec(camera.eye) - vec(camera.target));
  state.distance = glm::length(vec(back));
  state.orientation = orientationOf(back, camera.up);
  return state;
}

namespace {

// An empty or broken box: a point at the origin (fitCamera gives it 1 mm).
Bounds usable(Bounds b) {
  for (int k = 0; k < 3; ++k)
    if (!(b.min[k] <= b.max[k]) || !std::isfinite(b.min[k]) || !std::isfinite(b.max[k])) return Bounds{};
  return b;
}

// Whether `inner` lies within `outer` grown by `slack` of its diagonal.
bool within(const Bounds& inner, const Bounds& outer, double slack) {
  const double grow = slack * glm::length(vec(outer.max) - vec(outer.min));
  for (int k = 0; k < 3; ++k)
    if (inner.min[k] < outer.min[k] - grow || inner.max[k] > outer.max[k] + grow) return false;
  return true;
}

}  // namespace

void OrbitController::frame(const Bounds& bounds, std::span<const Vec3d> sample) {
  bounds_ = fitted_bounds_ = usable(bounds);
  sample_.assign(sample.begin(), sample.end());
  goal_ = shown_ = defaultState();
  fitted_distance_ = goal_.distance;
}

void OrbitController::refit(const Bounds& bounds, std::span<const Vec3d> sample) {
  const Bounds old = bounds_;
  bounds_ = usable(bounds);
  sample_.assign(sample.begin(), sample.end());
  fitted_distance_ = defaultState().distance;  // the dolly limits follow the new box
  if (!within(bounds_, old, kRefitSlack)) {
    const Quat kept = goal_.orientation;
    goal_ = fittedState(kept);
    fitted_bounds_ = bounds_;
  }
  goal_.distance = clampDistance(goal_.distance);
}

void OrbitController::reset() {
  fitted_bounds_ = bounds_;
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
  const Quat turn = glm::angleAxis(-radians(dx_px * kDegreesPerPixel), glm::dvec3(0, 1, 0)) *
                    glm::angleAxis(-radians(dy_px * kDegreesPerPixel), glm::dvec3(1, 0, 0));
  // Local axes: right-multiply (the rotation is expressed in the camera frame).
  goal_.orientation = unitOrIdentity(goal_.orientation * turn);
}

void OrbitController::pan(double dx_px, double dy_px) {
  if (!std::isfinite(dx_px) || !std::isfinite(dy_px)) return;
  // At the target's depth d the image spans 2 d tan(fov / 2) mm vertically
  // over `height` pixels (square pixels: the same scale horizontally). Moving
  // the eye and target by -delta moves every point of that plane by +delta
  // in view space at the same depth, i.e. by delta / mm_per_px pixels.
  const double mm_per_px =
      2 * goal_.distance * std::tan(radians(fov_y_deg_) / 2) / double(std::max<uint32_t>(viewport_height_, 1));
  const glm::dvec3 right = goal_.orientation * glm::dvec3(1, 0, 0);
  const glm::dvec3 up = goal_.orientation * glm::dvec3(0, 1, 0);
  // Window y points down: dragging down must move the point down, so the
  // target moves up.
  Vec3d target = array(vec(goal_.target) + right * (-dx_px * mm_per_px) + up * (dy_px * mm_per_px));
  // Keep the target within the box grown by its diagonal either side, so the
  // model cannot be lost far off screen.
  const double slack = 2 * boundingRadius(bounds_);
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
  // Shortest path (glm::slerp turns q into -q where that is nearer).
  shown_.orientation = unitOrIdentity(glm::slerp(shown_.orientation, goal_.orientation, 1 - keep));
  if (!animating()) shown_ = goal_;
}

bool OrbitController::animating() const {
  // Below these the motion is far under a pixel: 1e-6 of the distance, a
  // microradian.
  const double eps = 1e-6 * goal_.distance;
  return glm::length(vec(shown_.target) - vec(goal_.target)) > eps || std::fabs(shown_.distance - goal_.distance) > eps ||
         angleBetween(shown_.orientation, goal_.orientation) > 1e-6;
}

void OrbitController::finishAnimation() { shown_ = goal_; }

void OrbitController::setViewport(uint32_t width, uint32_t height) {
  if (width == 0 || height == 0) return;
  viewport_width_ = width;
  viewport_height_ = height;
}

Camera OrbitController::makeCamera(const State& state, uint32_t width, uint32_t height) const {
  const glm::dvec3 back = state.orientation * glm::dvec3(0, 0, 1);
  Camera camera;
  camera.target = state.target;
  camera.eye = array(vec(state.target) + back * state.distance);
  camera.up = axis(state.orientation, {0, 1, 0});
  camera.fov_y_deg = fov_y_deg_;
  camera.width = std::max<uint32_t>(width, 1);
  camera.height = std::max<uint32_t>(height, 1);
  // Near and far from the box corners' depths along the view direction with
  // a 1 % margin of the bounding radius; the box is convex, so its depth
  // range is its corners'. Near keeps a floor of 1e-4 of the distance when
  // the eye is inside (or right at) the box: the part behind it is clipped
  // anyway, and a tiny positive near keeps the matrices valid.
  const glm::dvec3 forward = -back;
  double min_depth = std::numeric_limits<double>::infinity(), max_depth = -min_depth;
  for (const Vec3d& corner : boundsCorners(bounds_)) {
    const double depth = glm::dot(vec(corner) - vec(camera.eye), forward);
    min_depth = std::min(min_depth, depth);
    max_depth = std::max(max_depth, depth);
  }
  const double margin = 0.01 * boundingRadius(bounds_);
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
