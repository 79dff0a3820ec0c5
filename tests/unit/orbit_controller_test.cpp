#include "app/viewer/orbit_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace fibscope {
namespace {

const Bounds kBox = {{-60, -80, -40}, {70, 90, 60}};

std::vector<Vec3d> boxSample(const Bounds& b, size_t count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3d> sample;
  for (size_t i = 0; i < count; ++i)
    sample.push_back({b.min[0] + u(rng) * (b.max[0] - b.min[0]), b.min[1] + u(rng) * (b.max[1] - b.min[1]),
                      b.min[2] + u(rng) * (b.max[2] - b.min[2])});
  return sample;
}

Vec3d sub(Vec3d a, Vec3d b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(Vec3d a, Vec3d b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double len(Vec3d a) { return std::sqrt(dot(a, a)); }
Vec3d unit(Vec3d a) { return {a[0] / len(a), a[1] / len(a), a[2] / len(a)}; }
Vec3d cross(Vec3d a, Vec3d b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
// The camera's up made orthogonal to the view direction (what viewMatrix uses).
Vec3d trueUp(const Camera& c) {
  const Vec3d f = unit(sub(c.target, c.eye));
  const Vec3d s = unit(cross(f, c.up));
  return cross(s, f);
}
Vec3d viewDirection(const Camera& c) { return unit(sub(c.target, c.eye)); }

// Window position (x right, y down, px) and clip depth of a world point.
std::array<double, 3> project(const Camera& camera, Vec3d p) {
  const std::array<double, 16> m = viewProjectionD(camera);
  double c[4];
  for (int r = 0; r < 4; ++r) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
  return {(c[0] / c[3] + 1) * camera.width / 2, (c[1] / c[3] + 1) * camera.height / 2, c[2] / c[3]};
}

void expectNear(Vec3d a, Vec3d b, double tolerance) {
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], tolerance) << "component " << k;
}

// Every camera is valid and sees all corners of the box within depth [0, 1]
// (when they lie in front of the eye: the eye may be inside after a dolly).
void expectEnclosesBounds(const Camera& camera, const Bounds& b) {
  ASSERT_NO_THROW(validateCamera(camera));
  const Vec3d f = viewDirection(camera);
  for (int i = 0; i < 8; ++i) {
    const Vec3d corner = {(i & 1) ? b.max[0] : b.min[0], (i & 2) ? b.max[1] : b.min[1],
                          (i & 4) ? b.max[2] : b.min[2]};
    if (dot(sub(corner, camera.eye), f) <= camera.near_mm) {
      EXPECT_LT(camera.near_mm, 1e-3 * len(sub(camera.target, camera.eye)) + 1e-9) << "near not at its floor";
      continue;
    }
    const double depth = project(camera, corner)[2];
    EXPECT_GE(depth, 0.0) << "corner " << i;
    EXPECT_LE(depth, 1.0) << "corner " << i;
  }
}

OrbitController framedController(uint32_t w = 320, uint32_t h = 240) {
  OrbitController controller;
  controller.setViewport(w, h);
  const std::vector<Vec3d> sample = boxSample(kBox, 500);
  controller.frame(kBox, sample);
  return controller;
}

TEST(OrbitController, frameGivesTheDefaultThreeQuarterViewOfRender) {
  OrbitController controller = framedController();
  const std::vector<Vec3d> sample = boxSample(kBox, 500);
  const Camera expected = snugCamera(sample, [&](double f) { return orbitCamera(kBox, 125, 20, 320, 240, f); });
  const Camera camera = controller.camera(320, 240);
  expectNear(camera.eye, expected.eye, 1e-6);
  expectNear(camera.target, expected.target, 1e-9);
  expectNear(trueUp(camera), trueUp(expected), 1e-9);
  EXPECT_FALSE(controller.animating());
  expectEnclosesBounds(camera, kBox);
}

TEST(OrbitController, updateIsFrameRateIndependent) {
  OrbitController a = framedController(), b = framedController();
  for (OrbitController* c : {&a, &b}) {
    c->rotate(130, -45);
    c->pan(25, 12);
    c->dolly(3);
  }
  for (int i = 0; i < 100; ++i) a.update(0.001);
  b.update(0.1);
  EXPECT_TRUE(a.animating());  // 100 ms is a bit over one time constant: not there yet
  const Camera ca = a.camera(320, 240), cb = b.camera(320, 240);
  expectNear(ca.eye, cb.eye, 1e-6);
  expectNear(ca.target, cb.target, 1e-6);
  expectNear(ca.up, cb.up, 1e-6);
  EXPECT_NEAR(a.distance(), b.distance(), 1e-6);
  // And it moved part of the way: neither the start nor the goal.
  const Camera goal = a.goalCamera(320, 240);
  EXPECT_GT(len(sub(ca.eye, goal.eye)), 1.0);
}

TEST(OrbitController, settlesOnEachStandardViewWithStandardViewsDirectionAndUp) {
  for (StandardView view : {StandardView::Sagittal, StandardView::Coronal, StandardView::Axial}) {
    OrbitController controller = framedController();
    controller.rotate(200, 300);  // from somewhere arbitrary
    controller.update(1.0);
    const double distance = controller.distance();
    controller.setStandardView(view);
    EXPECT_TRUE(controller.animating());
    for (int i = 0; i < 200 && controller.animating(); ++i) controller.update(1.0 / 60);
    EXPECT_FALSE(controller.animating());
    const Camera camera = controller.camera(320, 240);
    const Camera expected = standardView(kBox, view, 320, 240);
    expectNear(viewDirection(camera), viewDirection(expected), 1e-9);
    expectNear(trueUp(camera), trueUp(expected), 1e-9);
    EXPECT_NEAR(controller.distance(), distance, 1e-9 * distance);  // the framing distance is kept
    expectEnclosesBounds(camera, kBox);
  }
}

TEST(OrbitController, fullHorizontalDragReturnsToTheStart) {
  OrbitController controller = framedController();
  const Camera start = controller.camera(320, 240);
  const double full_turn_px = 360.0 / OrbitController::kDegreesPerPixel;
  for (int i = 0; i < 36; ++i) {  // in 36 mouse events, settling a little in between
    controller.rotate(full_turn_px / 36, 0);
    controller.update(0.005);
  }
  EXPECT_TRUE(controller.animating());
  controller.update(5.0);
  const Camera end = controller.camera(320, 240);
  expectNear(end.eye, start.eye, 1e-6);
  expectNear(trueUp(end), trueUp(start), 1e-9);
}

TEST(OrbitController, dragRightMovesTheSceneRight) {
  OrbitController controller = framedController();
  const Camera before = controller.camera(320, 240);
  // A point in front of the target (towards the eye) moves with the cursor.
  const Vec3d front = {before.target[0] + 0.3 * (before.eye[0] - before.target[0]),
                       before.target[1] + 0.3 * (before.eye[1] - before.target[1]),
                       before.target[2] + 0.3 * (before.eye[2] - before.target[2])};
  const auto p0 = project(before, front);
  controller.rotate(20, 0);
  controller.finishAnimation();
  EXPECT_GT(project(controller.camera(320, 240), front)[0], p0[0] + 1);
  controller.rotate(0, 20);
  controller.finishAnimation();
  EXPECT_GT(project(controller.camera(320, 240), front)[1], p0[1] + 1);  // drag down: down
}

TEST(OrbitController, orbitingOverThePoleKeepsAValidCameraAndContinuousUp) {
  OrbitController controller = framedController();
  Camera previous = controller.camera(320, 240);
  // 2 px steps vertically: 0.5 degrees per step, 3 full turns over both poles.
  const int steps = int(3 * 360 / (2 * OrbitController::kDegreesPerPixel));
  double max_up_change = 0;
  for (int i = 0; i < steps; ++i) {
    controller.rotate(0, 2);
    controller.update(1.0 / 120);
    const Camera camera = controller.camera(320, 240);
    expectEnclosesBounds(camera, kBox);
    max_up_change = std::max(max_up_change, len(sub(trueUp(camera), trueUp(previous))));
    previous = camera;
  }
  // A step rotates by at most a few degrees (the display lags but never jumps).
  EXPECT_LT(max_up_change, 2 * std::sin(3.0 * 3.14159265 / 180 / 2) * 2);
  controller.update(5.0);
  const Camera end = controller.camera(320, 240);
  // 3 full turns: back at the start.
  const Camera start = framedController().camera(320, 240);
  expectNear(end.eye, start.eye, 1e-6);
  expectNear(trueUp(end), trueUp(start), 1e-9);
}

TEST(OrbitController, panKeepsTheWorldPointUnderTheCursor) {
  for (auto [w, h] : {std::pair{320u, 240u}, std::pair{200u, 500u}}) {
    OrbitController controller = framedController(w, h);
    controller.rotate(77, -31);
    controller.dolly(2);
    controller.setFovY(50);
    controller.finishAnimation();
    const Camera before = controller.camera(w, h);
    // The world point at the target's depth under the cursor (100, 60):
    // unproject through the inverse of the view (a ray at that depth).
    const double cursor_x = 100, cursor_y = 60;
    const Vec3d f = viewDirection(before), up = trueUp(before), right = cross(f, up);
    const double d = len(sub(before.target, before.eye));
    const double half_h = d * std::tan(before.fov_y_deg * 3.14159265358979 / 360);
    const double half_w = half_h * double(w) / h;
    const double nx = 2 * cursor_x / w - 1, ny = 1 - 2 * cursor_y / h;  // y down in the window
    Vec3d world;
    for (int k = 0; k < 3; ++k) world[k] = before.target[k] + right[k] * nx * half_w + up[k] * ny * half_h;
    const auto p0 = project(before, world);
    ASSERT_NEAR(p0[0], cursor_x, 1e-6);
    ASSERT_NEAR(p0[1], cursor_y, 1e-6);
    controller.pan(37, -21);
    controller.update(10.0);
    const auto p1 = project(controller.camera(w, h), world);
    EXPECT_NEAR(p1[0], cursor_x + 37, 1e-6);
    EXPECT_NEAR(p1[1], cursor_y - 21, 1e-6);
    EXPECT_NEAR(p1[2], p0[2], 1e-9);
    expectEnclosesBounds(controller.camera(w, h), kBox);
  }
}

TEST(OrbitController, dollyMultipliesTheDistanceAndClamps) {
  OrbitController controller = framedController();
  const double fitted = controller.fittedDistance();
  EXPECT_NEAR(controller.distance(), fitted, 1e-9);
  controller.dolly(1);
  controller.finishAnimation();
  EXPECT_NEAR(controller.distance(), fitted / OrbitController::kDollyPerStep, 1e-9 * fitted);
  controller.dolly(-2);
  controller.finishAnimation();
  EXPECT_NEAR(controller.distance(), fitted * OrbitController::kDollyPerStep, 1e-9 * fitted);
  controller.dolly(1000);
  controller.finishAnimation();
  EXPECT_NEAR(controller.distance(), fitted / 50, 1e-9 * fitted);
  expectEnclosesBounds(controller.camera(320, 240), kBox);  // eye inside the box
  controller.dolly(-1000);
  controller.update(10);
  EXPECT_NEAR(controller.distance(), fitted * 20, 1e-9 * fitted);
  expectEnclosesBounds(controller.camera(320, 240), kBox);
}

TEST(OrbitController, fieldOfViewIsClamped) {
  OrbitController controller = framedController();
  controller.setFovY(5);
  EXPECT_EQ(controller.camera(320, 240).fov_y_deg, 10);
  controller.setFovY(120);
  EXPECT_EQ(controller.camera(320, 240).fov_y_deg, 90);
  controller.setFovY(45);
  EXPECT_EQ(controller.camera(320, 240).fov_y_deg, 45);
}

TEST(OrbitController, everyCameraIsValidAndEnclosesTheBounds) {
  OrbitController controller = framedController();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 300; ++i) {
    switch (i % 5) {
      case 0: controller.rotate(400 * u(rng), 400 * u(rng)); break;
      case 1: controller.pan(300 * u(rng), 300 * u(rng)); break;
      case 2: controller.dolly(20 * u(rng)); break;
      case 3: controller.setStandardView(StandardView(i % 3)); break;
      case 4: controller.setFovY(50 + 50 * u(rng)); break;
    }
    controller.update(0.03 * (u(rng) + 1));
    const uint32_t w = 1 + uint32_t(300 * (u(rng) + 1)), h = 1 + uint32_t(300 * (u(rng) + 1));
    expectEnclosesBounds(controller.camera(w, h), kBox);
  }
}

TEST(OrbitController, resetAnimatesBackToTheFramedView) {
  OrbitController controller = framedController();
  const Camera start = controller.camera(320, 240);
  controller.rotate(300, 100);
  controller.pan(50, 50);
  controller.dolly(5);
  controller.update(1.0);
  controller.reset();
  EXPECT_TRUE(controller.animating());
  controller.update(2.0);
  EXPECT_FALSE(controller.animating());
  const Camera end = controller.camera(320, 240);
  expectNear(end.eye, start.eye, 1e-6);
  expectNear(end.target, start.target, 1e-9);
}

// A model added within the scene (a bundled or filtered copy) or one closed
// leaves the user's rotated, panned and zoomed view exactly as it was.
TEST(OrbitController, refitWithinTheSceneKeepsTheView) {
  OrbitController controller = framedController();
  controller.rotate(300, 100);
  controller.pan(20, -10);
  controller.dolly(3);
  controller.update(2.0);
  const Camera before = controller.camera(320, 240);
  const Bounds inner = {{-40, -60, -20}, {72, 80, 50}};  // within kBox grown by 10 % of its diagonal
  controller.refit(inner, boxSample(inner, 300));
  EXPECT_FALSE(controller.animating());
  const Camera after = controller.camera(320, 240);
  expectNear(after.eye, before.eye, 1e-9);
  expectNear(after.target, before.target, 1e-9);
  expectNear(trueUp(after), trueUp(before), 1e-12);
  expectEnclosesBounds(after, inner);
  expectNear(controller.fittedBounds().min, kBox.min, 0);  // the view is still fitted to the old box
  expectNear(controller.fittedBounds().max, kBox.max, 0);
  // reset() now frames the new box: the default view of it.
  controller.reset();
  expectNear(controller.fittedBounds().max, inner.max, 0);
  controller.update(2.0);
  OrbitController fresh;
  fresh.setViewport(320, 240);
  fresh.frame(inner, boxSample(inner, 300));
  expectNear(controller.camera(320, 240).eye, fresh.camera(320, 240).eye, 1e-6);
}

// A model elsewhere: the orientation stays, target and distance frame the
// new scene snugly along it (every sample point within the image).
TEST(OrbitController, refitBeyondTheSceneKeepsTheOrientationAndFramesTheNewBox) {
  OrbitController controller = framedController();
  controller.rotate(-200, 150);
  controller.update(2.0);
  const Camera before = controller.camera(320, 240);
  const Bounds far_box = {{200, -80, -40}, {420, 90, 160}};
  Bounds both = kBox;
  for (int k = 0; k < 3; ++k) both.min[k] = std::min(kBox.min[k], far_box.min[k]), both.max[k] = std::max(kBox.max[k], far_box.max[k]);
  std::vector<Vec3d> sample = boxSample(kBox, 300), far_sample = boxSample(far_box, 300);
  sample.insert(sample.end(), far_sample.begin(), far_sample.end());
  controller.refit(both, sample);
  EXPECT_TRUE(controller.animating());
  controller.update(2.0);
  const Camera after = controller.camera(320, 240);
  expectNear(viewDirection(after), viewDirection(before), 1e-9);
  expectNear(trueUp(after), trueUp(before), 1e-9);
  expectEnclosesBounds(after, both);
  expectNear(controller.fittedBounds().min, both.min, 0);
  expectNear(controller.fittedBounds().max, both.max, 0);
  double extent = 0;
  for (const Vec3d& p : sample) {
    const auto w = project(after, p);
    EXPECT_GE(w[0], 0.0);
    EXPECT_LE(w[0], 320.0);
    EXPECT_GE(w[1], 0.0);
    EXPECT_LE(w[1], 240.0);
    extent = std::max({extent, std::fabs(w[0] - 160) / 160, std::fabs(w[1] - 120) / 120});
  }
  EXPECT_GT(extent, 0.8) << "snug, not merely inside";
  // The dolly limits follow the new scene.
  EXPECT_GT(controller.fittedDistance(), framedController().fittedDistance());
}

TEST(OrbitController, emptyOrDegenerateBoundsStillGiveAValidCamera) {
  OrbitController controller;
  controller.frame(Bounds{}, {});
  EXPECT_NO_THROW(validateCamera(controller.camera(64, 64)));
  Bounds flat = {{0, 0, 5}, {10, 10, 5}};
  controller.frame(flat, {});
  EXPECT_NO_THROW(validateCamera(controller.camera(64, 64)));
  controller.setStandardView(StandardView::Sagittal);  // edge-on view of the flat box
  controller.update(1);
  expectEnclosesBounds(controller.camera(64, 64), flat);
}

}  // namespace
}  // namespace fibscope
