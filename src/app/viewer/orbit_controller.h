// The viewer's camera: orbit, pan and dolly about a target, as mrview users
// expect, with a smooth, frame-rate independent approach of the displayed
// camera to the goal the input sets.
//
// State: a target point (world mm), an orientation (unit quaternion taking
// the camera's local axes to world axes: local +x = image right, +y = image
// up, +z = from the target towards the eye) and a distance from the target to
// the eye. Input (rotate, pan, dolly, setStandardView, reset) changes the
// GOAL state; update(dt) moves the DISPLAYED state towards it; camera() builds
// the displayed Camera. A quaternion instead of azimuth/elevation keeps
// orbiting continuous over the poles (no gimbal flip, no clamped elevation).
//
// No Vulkan, no GLFW: plain state the UI reads and writes, unit-tested on its
// own.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "render/camera.h"

namespace fibscope {

// Unit quaternion (w, x, y, z) as a rotation; identity by default.
using Quat = glm::dquat;

class OrbitController {
 public:
  // Left drag: degrees of rotation per pixel of mouse motion (a 1440 px drag
  // turns the view a full circle). Horizontal motion turns about the view's
  // up axis, vertical about its right axis; the scene follows the cursor
  // (drag right: the front of the model moves right).
  static constexpr double kDegreesPerPixel = 0.25;
  // Wheel: one step (one notch, +1 = away from the user = zoom in) divides
  // the distance by this factor.
  static constexpr double kDollyPerStep = 1.1;
  // The distance stays within [kMinDistanceFactor, kMaxDistanceFactor] x the
  // fitted distance (the distance frame() chose).
  static constexpr double kMinDistanceFactor = 1.0 / 50.0;
  static constexpr double kMaxDistanceFactor = 20.0;
  // Time constant of the approach to the goal: after t seconds the remaining
  // difference is exp(-t / kTimeConstant) of what it was (63 % in 80 ms,
  // 99 % in 370 ms), whatever the frame rate.
  static constexpr double kTimeConstantSeconds = 0.080;
  // The default view (the one `fibscope render` uses without --camera).
  static constexpr double kDefaultAzimuthDeg = 125.0;
  static constexpr double kDefaultElevationDeg = 20.0;
  static constexpr double kMinFovDeg = 10.0, kMaxFovDeg = 90.0;

  OrbitController();

  // Reset to the three-quarter default view (azimuth 125, elevation 20,
  // orbitCamera's conventions) looking at the box centre, at the distance
  // that frames `sample` snugly (snugCamera; the box's corners when the
  // sample is empty) for the last viewport size and field of view. The
  // displayed camera jumps there (the first model); remembers bounds and sample
  // for reset() and for the near/far planes.
  void frame(const Bounds& bounds, std::span<const Vec3d> sample);
  // A model added or closed while others are shown: remembers the new
  // bounds and sample as frame() does (reset() and the near/far planes use
  // them) without taking the user's view away, as mrview keeps it when a
  // tractogram is added. Where the new box lies within the old one grown by
  // kRefitSlack of its diagonal (a bundled or filtered copy, a model
  // closed) the view stays as it is; otherwise the orientation stays and
  // the target and distance frame the new box snugly along it. Animated.
  void refit(const Bounds& bounds, std::span<const Vec3d> sample);
  static constexpr double kRefitSlack = 0.10;
  // The reset key: animates back to the view frame() chose (re-fitted for the
  // current viewport and field of view).
  void reset();

  // Left drag by (dx, dy) window pixels (y down).
  void rotate(double dx_px, double dy_px);
  // Middle (or shift-left) drag by (dx, dy) window pixels (y down): moves the
  // target in the view plane so that the point at the target's depth under
  // the cursor follows the cursor exactly, for the height of the last
  // viewport given to camera() or setViewport() and the vertical field of
  // view (measured on the goal state, so it holds once the motion settles).
  void pan(double dx_px, double dy_px);
  // Wheel: distance *= pow(kDollyPerStep, -steps), clamped (see above).
  void dolly(double wheel_steps);
  // Animates to the standard view of camera.h (the same eye direction and up
  // as standardView), keeping the current target and distance.
  void setStandardView(StandardView view);
  // Animates the target to `point` (e.g. a picked fiber's world position).
  void lookAt(const Vec3d& point);
  // Clamped to [10, 90] degrees; applies at once (no animation).
  void setFovY(double degrees);
  double fovY() const { return fov_y_deg_; }

  // Advances the displayed state by dt seconds towards the goal (dt <= 0
  // does nothing). update(a) then update(b) equals update(a + b) up to
  // rounding: target linear, distance in log space, orientation by slerp,
  // each with the remaining difference scaled by exp(-dt / kTimeConstant).
  void update(double dt_seconds);
  // Whether the displayed state still differs from the goal (false once it
  // has settled within rounding; update() then snaps it).
  bool animating() const;
  // Jumps the displayed state to the goal.
  void finishAnimation();

  // The viewport size pan() and frame() use; camera() records it as well.
  void setViewport(uint32_t width, uint32_t height);
  // The displayed camera for a width x height image (both >= 1). Valid for
  // validateCamera; near and far enclose the whole bounds (nothing is
  // clipped), near > 0 even when the eye is inside the box.
  Camera camera(uint32_t width, uint32_t height) const;
  // The camera of the goal state (where the animation ends).
  Camera goalCamera(uint32_t width, uint32_t height) const;

  const Bounds& bounds() const { return bounds_; }
  // The box the view's distance was last fitted to (frame(), reset(), a
  // refit beyond the scene); after a refit that kept the view, the older
  // box (the split view scales its halves by it).
  const Bounds& fittedBounds() const { return fitted_bounds_; }
  Vec3d target() const { return shown_.target; }
  double distance() const { return shown_.distance; }
  double fittedDistance() const { return fitted_distance_; }
  Quat orientation() const { return shown_.orientation; }

 private:
  struct State {
    Vec3d target = {0, 0, 0};
    Quat orientation;
    double distance = 100;
  };
  Camera makeCamera(const State& state, uint32_t width, uint32_t height) const;
  State defaultState() const;
  // The snug fit of bounds_ / sample_ seen along `orientation`.
  State fittedState(const Quat& orientation) const;
  // The state of a camera (its eye, target and up).
  static State stateOf(const Camera& camera);
  double clampDistance(double distance) const;

  Bounds bounds_;
  Bounds fitted_bounds_;
  std::vector<Vec3d> sample_;
  State shown_, goal_;
  double fitted_distance_ = 100;
  double fov_y_deg_ = 30;
  // Last viewport size (camera() is const but records it: the size the user
  // sees is the one pan() must match).
  mutable uint32_t viewport_width_ = 1280, viewport_height_ = 720;
};

}  // namespace fibscope
