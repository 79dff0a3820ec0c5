// Camera conventions, the CPU reference rasteriser's pixel rule and the
// image-comparison metrics (src/render/).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/png_writer.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/camera.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/camera.h"
#include "shared/render_config.h"
#include "test_support.h"

namespace fibscope {
namespace {

struct Projected {
  double x, y, depth;
};

// World -> window with the library's matrix (for the view tests that rely
// on the hand-checked matrix tests below).
Projected project(const Camera& camera, Vec3d p) {
  const auto m = viewProjectionD(camera);
  double c[4];
  for (int r = 0; r < 4; ++r) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
  return {(c[0] / c[3] + 1) * camera.width / 2, (c[1] / c[3] + 1) * camera.height / 2, c[2] / c[3]};
}

// The camera of most tests: on +z looking at the origin, up +y, so view
// space is world space shifted by 100 mm: x_view = x, y_view = y,
// z_view = z - 100.
Camera axisCamera(uint32_t width = 200, uint32_t height = 100) {
  Camera camera;
  camera.eye = {0, 0, 100};
  camera.target = {0, 0, 0};
  camera.up = {0, 1, 0};
  camera.fov_y_deg = 30;
  camera.near_mm = 10;
  camera.far_mm = 1000;
  camera.width = width;
  camera.height = height;
  return camera;
}

// Hand-written projection for axisCamera-like cameras (eye on +z, up +y):
// perspective divide by the distance in front of the eye, y flipped,
// depth = f / (f - n) * (1 - n / distance).
Projected handProject(const Camera& camera, Vec3d p) {
  const double g = 1 / std::tan(camera.fov_y_deg / 2 * std::numbers::pi / 180);
  const double aspect = double(camera.width) / camera.height;
  const double distance = camera.eye[2] - p[2];
  const double n = camera.near_mm, f = camera.far_mm;
  return {(1 + g / aspect * p[0] / distance) * camera.width / 2, (1 - g * p[1] / distance) * camera.height / 2,
          f / (f - n) * (1 - n / distance)};
}

TEST(Camera, MatricesHaveTheHandComputedEntries) {
  const Camera camera = axisCamera();
  const Mat4 view = viewMatrix(camera);
  const Mat4 expected_view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -100, 1};
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(view[i], expected_view[i], 1e-6) << "view[" << i << "]";
  const Mat4 proj = projectionMatrix(camera);
  const double g = 1 / std::tan(15 * std::numbers::pi / 180);  // 3.7320508
  const Mat4 expected_proj = {float(g / 2), 0, 0, 0,  0, float(-g), 0, 0,
                              0, 0, float(1000.0 / -990.0), -1,  0, 0, float(10000.0 / -990.0), 0};
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(proj[i], expected_proj[i], 1e-5) << "projection[" << i << "]";
}

TEST(Camera, PointOnTheViewAxisLandsOnTheImageCentreAtTheExpectedDepth) {
  const Camera camera = axisCamera();
  const Projected p = project(camera, {0, 0, 0});
  EXPECT_NEAR(p.x, 100.0, 1e-9);
  EXPECT_NEAR(p.y, 50.0, 1e-9);
  EXPECT_NEAR(p.depth, 1000.0 / 990.0 * 0.9, 1e-12);  // f/(f-n) * (1 - n/100)
}

TEST(Camera, NearPlaneIsDepthZeroAndFarPlaneIsDepthOne) {
  const Camera camera = axisCamera();
  EXPECT_NEAR(project(camera, {0, 0, 90}).depth, 0.0, 1e-12);
  EXPECT_NEAR(project(camera, {0, 0, -900}).depth, 1.0, 1e-12);
  EXPECT_NEAR(project(camera, {3, -2, 90}).depth, 0.0, 1e-12);  // the plane, not the sphere
  EXPECT_LT(project(camera, {0, 0, 95}).depth, 0.0);            // between eye and near plane
  EXPECT_GT(project(camera, {0, 0, -950}).depth, 1.0);
}

TEST(Camera, ImageYPointsDownAndXRight) {
  const Camera camera = axisCamera();
  const Projected up = project(camera, {0, 10, 0});
  const Projected right = project(camera, {10, 0, 0});
  const Projected hand_up = handProject(camera, {0, 10, 0});
  const Projected hand_right = handProject(camera, {10, 0, 0});
  EXPECT_LT(up.y, 50.0);  // world +y = view up = towards the top row
  EXPECT_NEAR(up.y, hand_up.y, 1e-9);
  EXPECT_NEAR(up.x, 100.0, 1e-9);
  EXPECT_GT(right.x, 100.0);
  EXPECT_NEAR(right.x, hand_right.x, 1e-9);
  EXPECT_NEAR(right.y, 50.0, 1e-9);
}

TEST(Camera, StandardViewsPutAnatomyWhereExpected) {
  const Bounds brain{{-70, -85, -60}, {70, 85, 60}};
  const uint32_t w = 300, h = 200;
  const Camera sagittal = standardView(brain, StandardView::Sagittal, w, h);
  const Camera coronal = standardView(brain, StandardView::Coronal, w, h);
  const Camera axial = standardView(brain, StandardView::Axial, w, h);
  const Vec3d anterior = {0, 50, 0}, superior = {0, 0, 50}, right = {50, 0, 0};
  // Sagittal, seen from the subject's right: anterior to the image's right, superior up.
  EXPECT_GT(project(sagittal, anterior).x, w / 2.0 + 10);
  EXPECT_LT(project(sagittal, superior).y, h / 2.0 - 10);
  EXPECT_NEAR(project(sagittal, right).x, w / 2.0, 1e-6);
  // Coronal, facing the subject: the subject's right on the image's left, superior up.
  EXPECT_LT(project(coronal, right).x, w / 2.0 - 10);
  EXPECT_LT(project(coronal, superior).y, h / 2.0 - 10);
  // Axial, from above: anterior up, the subject's right on the image's right.
  EXPECT_LT(project(axial, anterior).y, h / 2.0 - 10);
  EXPECT_GT(project(axial, right).x, w / 2.0 + 10);
  EXPECT_EQ(sagittal.eye[1], 0.0);
  EXPECT_GT(sagittal.eye[0], 70.0);
  EXPECT_GT(coronal.eye[1], 85.0);
  EXPECT_GT(axial.eye[2], 60.0);
}

TEST(Camera, FittedCamerasSeeEveryCornerOfTheBoxUnclipped) {
  const Bounds box{{-70, -85, -60}, {70, 85, 60}};
  for (const auto& [az, el] : std::vector<std::pair<double, double>>{
           {0, 0}, {90, 0}, {33, 20}, {200, -45}, {-90, 90}, {10, -90}}) {
    for (const auto& [w, h] : std::vector<std::pair<uint32_t, uint32_t>>{{256, 256}, {1920, 1080}, {100, 300}}) {
      const Camera camera = orbitCamera(box, az, el, w, h);
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3d p = {corner & 1 ? box.max[0] : box.min[0], corner & 2 ? box.max[1] : box.min[1],
                         corner & 4 ? box.max[2] : box.min[2]};
        const Projected q = project(camera, p);
        SCOPED_TRACE("azimuth " + std::to_string(az) + " elevation " + std::to_string(el) + " corner " +
                     std::to_string(corner));
        EXPECT_GE(q.x, 0.0);
        EXPECT_LE(q.x, double(w));
        EXPECT_GE(q.y, 0.0);
        EXPECT_LE(q.y, double(h));
        EXPECT_GT(q.depth, 0.0);
        EXPECT_LT(q.depth, 1.0);
      }
    }
  }
  // Orbit (0, 0) looks from the right with superior up, like the sagittal view.
  const Camera orbit = orbitCamera(box, 0, 0, 256, 256);
  const Camera sagittal = standardView(box, StandardView::Sagittal, 256, 256);
  const Mat4 a = viewProjection(orbit), b = viewProjection(sagittal);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(a[i], b[i], 1e-5);
}

TEST(Camera, SnugCameraFramesThePointsWithinTheMarginAndNoCloser) {
  // Points of an ellipsoid inside a box: the box's bounding sphere leaves
  // them small on screen; the snug camera brings them to the margin.
  const Bounds box{{-70, -85, -60}, {70, 85, 60}};
  std::vector<Vec3d> points;
  for (int i = 0; i < 400; ++i) {
    const double u = 0.1 + 3.0 * i / 400, v = 0.37 * i;
    points.push_back({60 * std::sin(u) * std::cos(v), 75 * std::sin(u) * std::sin(v), 50 * std::cos(u)});
  }
  for (const auto& [w, h] : std::vector<std::pair<uint32_t, uint32_t>>{{256, 256}, {1920, 1080}}) {
    auto make = [&](double f) { return orbitCamera(box, 125, 20, w, h, f); };
    const Camera camera = snugCamera(points, make, 0.9);
    double widest = 0;  // the largest |ndc| over the points
    for (const Vec3d& p : points) {
      const Projected q = project(camera, p);
      widest = std::max({widest, std::fabs(2 * q.x / w - 1), std::fabs(2 * q.y / h - 1)});
      EXPECT_GT(q.depth, 0.0);
    }
    EXPECT_LE(widest, 0.9 + 1e-9);
    EXPECT_GT(widest, 0.89) << "a closer camera would still fit";
  }
}

TEST(Camera, InvalidCamerasAreRejected) {
  Camera camera = axisCamera();
  camera.up = {0, 0, 1};  // parallel to the view direction
  EXPECT_THROW(viewMatrix(camera), Error);
  camera = axisCamera();
  camera.near_mm = 0;
  EXPECT_THROW(projectionMatrix(camera), Error);
  camera = axisCamera();
  camera.far_mm = camera.near_mm;
  EXPECT_THROW(projectionMatrix(camera), Error);
  camera = axisCamera();
  camera.target = camera.eye;
  EXPECT_THROW(viewMatrix(camera), Error);
  camera = axisCamera();
  camera.width = 0;
  EXPECT_THROW(viewProjection(camera), Error);
}

TEST(Camera, ShaderBlockTransformsLikeTheMatrix) {
  const Camera camera = orbitCamera(Bounds{{-70, -85, -60}, {70, 85, 60}}, 30, 25, 640, 480);
  shader::CameraBlock block = makeCameraBlock(camera, 2.0f);
  EXPECT_EQ(block.viewport.x, 640.0f);
  EXPECT_EQ(block.viewport.y, 480.0f);
  EXPECT_EQ(block.viewport.z, 2.0f);
  EXPECT_FLOAT_EQ(block.depth_range.x, float(camera.near_mm));
  const auto vp = viewProjectionD(camera);
  for (const Vec3d p : {Vec3d{0, 0, 0}, Vec3d{40, -30, 20}, Vec3d{-70, 85, -60}}) {
    const shader::vec4 c = shader::cameraTransformPoint(block.view_projection,
                                                        shader::vec3(float(p[0]), float(p[1]), float(p[2])));
    const float got[4] = {c.x, c.y, c.z, c.w};
    for (int r = 0; r < 4; ++r) {
      const double want = vp[r] * p[0] + vp[4 + r] * p[1] + vp[8 + r] * p[2] + vp[12 + r];
      EXPECT_NEAR(got[r], want, 1e-4 * (1 + std::fabs(want)));
    }
  }
}

// --- the pixel rule ---------------------------------------------------------

// Distance from (cx, cy) to segment ab, written differently from the
// rasteriser: perpendicular distance to the line where the foot lies
// between the ends, else the nearer end.
double segmentDistance(double cx, double cy, double ax, double ay, double bx, double by) {
  const double ux = bx - ax, uy = by - ay;
  const double len = std::hypot(ux, uy);
  const double da = std::hypot(cx - ax, cy - ay), db = std::hypot(cx - bx, cy - by);
  if (len == 0) return da;
  const double along = ((cx - ax) * ux + (cy - ay) * uy) / len;
  if (along < 0 || along > len) return std::min(da, db);
  return std::fabs((cx - ax) * uy - (cy - ay) * ux) / len;
}

std::vector<uint8_t> bruteForceCoverage(uint32_t w, uint32_t h, double ax, double ay, double bx, double by,
                                        double line_width) {
  std::vector<uint8_t> mask(size_t(w) * h, 0);
  for (uint32_t py = 0; py < h; ++py)
    for (uint32_t px = 0; px < w; ++px)
      mask[size_t(py) * w + px] = segmentDistance(px + 0.5, py + 0.5, ax, ay, bx, by) <= line_width / 2 ? 1 : 0;
  return mask;
}

struct WindowCase {
  const char* name;
  double ax, ay, bx, by;
};

TEST(ReferenceRaster, SegmentCoversExactlyThePixelCentresWithinHalfTheWidth) {
  // Ends chosen off the half-pixel grid, so no pixel centre lies exactly at
  // distance width / 2 (where rounding could decide either way).
  const WindowCase cases[] = {{"horizontal", 10.2, 20.3, 40.7, 20.3},
                              {"vertical", 30.6, 5.1, 30.6, 50.9},
                              {"diagonal", 5.33, 7.91, 57.12, 44.23},
                              {"steep reversed", 50.2, 60.7, 41.9, 3.4},
                              {"a dot", 20.23, 20.11, 20.23, 20.11},
                              {"leaving the image", -30.3, 10.2, 80.4, 70.6}};
  for (const WindowCase& c : cases) {
    for (const float width : {1.0f, 1.7f, 2.0f, 3.0f, 4.0f}) {
      SCOPED_TRACE(std::string(c.name) + " width " + std::to_string(width));
      ReferenceFrame frame(64, 64);
      rasterizeWindowSegment(frame, {c.ax, c.ay, 0.5}, {c.bx, c.by, 0.5}, 3, 7, {1, 0, 0}, width);
      const std::vector<uint8_t> want = bruteForceCoverage(64, 64, c.ax, c.ay, c.bx, c.by, width);
      const std::vector<uint8_t> got = frame.coverageMask();
      size_t wrong = 0;
      for (size_t i = 0; i < want.size(); ++i) wrong += want[i] != got[i];
      EXPECT_EQ(wrong, 0u);
      EXPECT_GT(frame.coveredPixels(), 0u);
      for (size_t i = 0; i < got.size(); ++i) {
        if (!got[i]) continue;
        EXPECT_EQ(frame.fiber[i], 3u);
        EXPECT_EQ(frame.point[i], 7u);
        EXPECT_EQ(frame.fragments[i], 1u);
      }
    }
  }
  // A horizontal width-1 segment on row 20 covers just that row's centres
  // between its ends (caps add nothing: the rows above and below are 1 px away).
  ReferenceFrame frame(64, 64);
  rasterizeWindowSegment(frame, {10.2, 20.3, 0}, {40.7, 20.3, 0}, 0, 0, {1, 0, 0}, 1.0f);
  EXPECT_EQ(frame.coveredPixels(), 31u);  // centres 10.5 .. 40.5
  EXPECT_TRUE(frame.covered(10, 20));
  EXPECT_TRUE(frame.covered(40, 20));
  EXPECT_FALSE(frame.covered(9, 20));
  EXPECT_FALSE(frame.covered(41, 20));
}

TEST(ReferenceRaster, DepthIsInterpolatedAtTheClosestPointOfTheSegment) {
  ReferenceFrame frame(64, 64);
  const double ax = 10.2, bx = 40.7, y = 20.3;
  rasterizeWindowSegment(frame, {ax, y, 0.2}, {bx, y, 0.8}, 0, 0, {1, 0, 0}, 3.0f);
  size_t checked = 0;
  for (uint32_t py = 0; py < 64; ++py)
    for (uint32_t px = 0; px < 64; ++px) {
      if (!frame.covered(px, py)) continue;
      // Horizontal segment: the closest point has the pixel's x, clamped to the ends.
      const double t = std::clamp((px + 0.5 - ax) / (bx - ax), 0.0, 1.0);
      EXPECT_NEAR(frame.depth[frame.index(px, py)], 0.2 + 0.6 * t, 1e-6) << px << "," << py;
      ++checked;
    }
  EXPECT_GT(checked, 80u);
}

TEST(ReferenceRaster, WorldSegmentMatchesTheHandProjectionAndPerspectiveDepth) {
  const Camera camera = axisCamera(160, 120);
  const Vec3d p0 = {-12, -5, 0}, p1 = {14, 9, -300};
  Tractogram t;
  const float xyz[6] = {float(p0[0]), float(p0[1]), float(p0[2]), float(p1[0]), float(p1[1]), float(p1[2])};
  t.addStreamline(xyz, 2);
  const ReferenceFrame frame = rasterizeReference(t, camera, 2.0f);
  const Projected a = handProject(camera, p0), b = handProject(camera, p1);
  const std::vector<uint8_t> want = bruteForceCoverage(160, 120, a.x, a.y, b.x, b.y, 2.0);
  const CoverageComparison cmp = compareCoverage(frame.coverageMask(), want, 160, 120);
  EXPECT_EQ(cmp.agreement, 1.0) << cmp.summary();
  const double length = std::hypot(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
  size_t checked = 0;
  for (uint32_t py = 0; py < 120; ++py)
    for (uint32_t px = 0; px < 160; ++px) {
      const size_t i = frame.index(px, py);
      if (!frame.covered(px, py)) continue;
      EXPECT_NEAR(frame.tangent[i][0], (p1[0] - p0[0]) / length, 1e-6);
      EXPECT_NEAR(frame.tangent[i][2], (p1[2] - p0[2]) / length, 1e-6);
      // The window point closest to the centre is at window parameter t;
      // the 3D point that projects there is at s = t w0 / ((1 - t) w1 + t w0)
      // (w = distance in front of the eye), and its depth is the hand formula.
      const double dx = b.x - a.x, dy = b.y - a.y;
      const double t_window =
          std::clamp(((px + 0.5 - a.x) * dx + (py + 0.5 - a.y) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
      const double w0 = camera.eye[2] - p0[2], w1 = camera.eye[2] - p1[2];
      const double s = t_window * w0 / ((1 - t_window) * w1 + t_window * w0);
      const Vec3d q = {p0[0] + s * (p1[0] - p0[0]), p0[1] + s * (p1[1] - p0[1]), p0[2] + s * (p1[2] - p0[2])};
      EXPECT_NEAR(frame.depth[i], handProject(camera, q).depth, 2e-6) << px << "," << py;
      ++checked;
    }
  EXPECT_GT(checked, 50u);
}

TEST(ReferenceRaster, NearestDepthWinsWhereSegmentsCross) {
  const Camera camera = axisCamera(100, 100);
  Tractogram t;
  const float far_one[6] = {-20, 0, -10, 20, 0, -10};   // horizontal, 110 mm away
  const float near_one[6] = {0, -20, 10, 0, 20, 10};    // vertical, 90 mm away
  t.addStreamline(far_one, 2);
  t.addStreamline(near_one, 2);
  const ReferenceFrame frame = rasterizeReference(t, camera, 1.0f);
  const Projected centre = handProject(camera, {0, 0, 10});
  const uint32_t px = uint32_t(centre.x), py = uint32_t(centre.y);
  ASSERT_TRUE(frame.covered(px, py));
  EXPECT_EQ(frame.fiber[frame.index(px, py)], 1u);
  EXPECT_EQ(frame.fragments[frame.index(px, py)], 2u);
  EXPECT_NEAR(frame.depth[frame.index(px, py)], centre.depth, 1e-6);
  EXPECT_NEAR(frame.tangent[frame.index(px, py)][1], 1.0f, 1e-6);
  // Swapping the two streamlines swaps the ids but not the winner.
  Tractogram swapped;
  swapped.addStreamline(near_one, 2);
  swapped.addStreamline(far_one, 2);
  const ReferenceFrame frame2 = rasterizeReference(swapped, camera, 1.0f);
  EXPECT_EQ(frame2.fiber[frame2.index(px, py)], 0u);
  EXPECT_EQ(frame2.depth, frame.depth);
}

TEST(ReferenceRaster, EqualDepthsGoToTheSmallerFiberAndPoint) {
  for (const bool reversed : {false, true}) {
    ReferenceFrame frame(32, 32);
    const auto draw_a = [&] { rasterizeWindowSegment(frame, {2.2, 16.2, 0.5}, {29.9, 16.2, 0.5}, 5, 1, {1, 0, 0}, 1); };
    const auto draw_b = [&] { rasterizeWindowSegment(frame, {16.3, 2.1, 0.5}, {16.3, 29.8, 0.5}, 2, 9, {0, 1, 0}, 1); };
    const auto draw_c = [&] { rasterizeWindowSegment(frame, {2.2, 2.2, 0.5}, {29.9, 29.9, 0.5}, 2, 4, {0, 0, 1}, 1); };
    if (reversed) {
      draw_c(), draw_b(), draw_a();
    } else {
      draw_a(), draw_b(), draw_c();
    }
    EXPECT_EQ(frame.fiber[frame.index(16, 16)], 2u);
    EXPECT_EQ(frame.point[frame.index(16, 16)], 4u);
    EXPECT_EQ(frame.fragments[frame.index(16, 16)], 3u);
    EXPECT_EQ(frame.fiber[frame.index(20, 16)], 5u);
  }
}

TEST(ReferenceRaster, SegmentCrossingTheNearPlaneIsClippedThere) {
  const Camera camera = axisCamera(120, 120);  // near plane at world z = 90
  const float crossing[6] = {-5, -3, 0, 3, 2, 120};  // ends behind the eye (z > 100)
  // The same line cut by hand where it meets z = 90: s = 90 / 120.
  const float cut[6] = {-5, -3, 0, -5 + 8 * 0.75f, -3 + 5 * 0.75f, 90};
  Tractogram a, b;
  a.addStreamline(crossing, 2);
  b.addStreamline(cut, 2);
  const ReferenceFrame fa = rasterizeReference(a, camera, 1.0f);
  const ReferenceFrame fb = rasterizeReference(b, camera, 1.0f);
  const CoverageComparison cmp = compareCoverage(fa.coverageMask(), fb.coverageMask(), 120, 120);
  EXPECT_GT(fa.coveredPixels(), 20u);
  EXPECT_GE(cmp.agreement, 0.99) << cmp.summary();
  EXPECT_LE(cmp.maxDistance(), 1.0) << cmp.summary();
  float min_depth = 2;
  for (float d : fa.depth)
    if (d != kEmptyDepth) min_depth = std::min(min_depth, d);
  EXPECT_GE(min_depth, 0.0f);
  EXPECT_LT(min_depth, 0.02f);
  // Entirely behind the eye, entirely between eye and near plane, entirely
  // beyond the far plane: nothing.
  for (const std::array<float, 6>& seg : {std::array<float, 6>{-5, -3, 110, 3, 2, 150},
                                          std::array<float, 6>{-1, 0, 92, 1, 0, 98},
                                          std::array<float, 6>{-50, 0, -950, 50, 0, -980}}) {
    Tractogram c;
    c.addStreamline(seg.data(), 2);
    EXPECT_EQ(rasterizeReference(c, camera, 2.0f).coveredPixels(), 0u);
  }
}

TEST(ReferenceRaster, FrameDoesNotDependOnDrawingOrder) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-10, 74), depth(0, 1);
  std::uniform_int_distribution<int> small(0, 3);  // few ids and quantised depths: many ties
  struct Seg {
    WindowVertex a, b;
    uint32_t fiber, point;
  };
  std::vector<Seg> segs;
  for (int i = 0; i < 400; ++i) {
    const double d = small(rng) / 4.0;
    segs.push_back({{pos(rng), pos(rng), d}, {pos(rng), pos(rng), small(rng) ? d : depth(rng)}, uint32_t(small(rng)),
                    uint32_t(i % 5)});
  }
  const auto draw = [&](const std::vector<Seg>& list) {
    ReferenceFrame frame(64, 64);
    for (const Seg& s : list)
      rasterizeWindowSegment(frame, s.a, s.b, s.fiber, s.point, {float(s.fiber), 0, 0}, 2.5f);
    return frame;
  };
  const ReferenceFrame first = draw(segs);
  std::shuffle(segs.begin(), segs.end(), rng);
  const ReferenceFrame second = draw(segs);
  EXPECT_EQ(first.depth, second.depth);
  EXPECT_EQ(first.fiber, second.fiber);
  EXPECT_EQ(first.point, second.point);
  EXPECT_EQ(first.tangent, second.tangent);
  EXPECT_EQ(first.fragments, second.fragments);
  // And a tractogram renders the same twice.
  const Tractogram t = test::smallTractogram(100, 3);
  const Camera camera = orbitCamera(tractogramBounds(t), 20, 30, 128, 96);
  const ReferenceFrame r1 = rasterizeReference(t, camera, 1.5f), r2 = rasterizeReference(t, camera, 1.5f);
  EXPECT_EQ(r1.depth, r2.depth);
  EXPECT_EQ(r1.fiber, r2.fiber);
  EXPECT_GT(r1.coveredPixels(), 100u);
}

TEST(ReferenceRaster, RejectsLineWidthsOutsideOneToFour) {
  const Tractogram t = test::smallTractogram(3);
  const Camera camera = orbitCamera(tractogramBounds(t), 0, 0, 32, 32);
  EXPECT_THROW(rasterizeReference(t, camera, 0.5f), Error);
  EXPECT_THROW(rasterizeReference(t, camera, 4.5f), Error);
  EXPECT_THROW(rasterizeReference(t, camera, std::numeric_limits<float>::quiet_NaN()), Error);
  EXPECT_NO_THROW(rasterizeReference(t, camera, 4.0f));
}

Tractogram readPhantom(const PhantomOptions& options) {
  return readAllStreamlines(*openPhantom(options));
}

TEST(ReferenceRaster, PhantomInTheStandardViewsLooksLikeABrain) {
  PhantomOptions options;
  options.streamlines = 300;
  options.step_mm = 0.5;
  options.threads = 1;
  const Tractogram phantom = readPhantom(options);
  ASSERT_EQ(phantom.streamlineCount(), 300u);
  ASSERT_EQ(phantom.per_streamline.size(), 1u);
  const std::vector<float>& bundle = phantom.per_streamline[0].values;
  const Bounds bounds = tractogramBounds(phantom);
  test::TempDir dir;
  // FIBSCOPE_TEST_IMAGE_DIR keeps the images for a person to look at.
  const char* keep = std::getenv("FIBSCOPE_TEST_IMAGE_DIR");
  const uint32_t size = 256;
  const std::pair<StandardView, const char*> views[] = {
      {StandardView::Sagittal, "sagittal"}, {StandardView::Coronal, "coronal"}, {StandardView::Axial, "axial"}};
  for (const auto& [view, name] : views) {
    SCOPED_TRACE(name);
    const Camera camera = standardView(bounds, view, size, size);
    const ReferenceFrame frame = rasterizeReference(phantom, camera, 1.0f);
    const double fraction = double(frame.coveredPixels()) / (size * size);
    EXPECT_GT(fraction, 0.05);
    EXPECT_LT(fraction, 0.6);
    // Inside the frame: every point projects into the image in front of the
    // far plane, and the border rows and columns stay empty.
    for (size_t i = 0; i < phantom.pointCount(); i += 7) {
      const float* p = phantom.point(i);
      const Projected q = project(camera, {p[0], p[1], p[2]});
      ASSERT_TRUE(q.x > 1 && q.x < size - 1 && q.y > 1 && q.y < size - 1 && q.depth > 0 && q.depth < 1)
          << "point " << i;
    }
    for (uint32_t k = 0; k < size; ++k) {
      EXPECT_FALSE(frame.covered(k, 0) || frame.covered(k, size - 1) || frame.covered(0, k) ||
                   frame.covered(size - 1, k));
    }
    // The left corticospinal tract (x < 0) is on the image's right in the
    // coronal view (radiological) and on the image's left in the axial view
    // (seen from above); it runs top to bottom in sagittal and coronal.
    double sum_x = 0, min_y = size, max_y = 0;
    size_t cst_left = 0;
    for (uint32_t py = 0; py < size; ++py)
      for (uint32_t px = 0; px < size; ++px) {
        const uint32_t fiber = frame.fiber[frame.index(px, py)];
        if (fiber == kNoFiber || bundle[fiber] != float(PhantomBundle::CstLeft)) continue;
        sum_x += px + 0.5;
        min_y = std::min(min_y, py + 0.5);
        max_y = std::max(max_y, py + 0.5);
        ++cst_left;
      }
    ASSERT_GT(cst_left, 20u);
    const double mean_x = sum_x / double(cst_left);
    if (view == StandardView::Coronal) {
      EXPECT_GT(mean_x, size / 2.0);
    }
    if (view == StandardView::Axial) {
      EXPECT_LT(mean_x, size / 2.0);
    } else {
      EXPECT_GT(max_y - min_y, size / 3.0);
    }
    const std::vector<uint8_t> rgba = shadeOrientation(frame);
    const std::string file = std::string("phantom_") + name + ".png";
    writePngRgba(dir.file(file), size, size, rgba);
    EXPECT_GT(test::readBytes(dir.file(file)).size(), 1000u);
    if (keep) writePngRgba(std::string(keep) + "/" + file, size, size, rgba);
  }
}

// --- image comparison -----------------------------------------------------

std::vector<uint8_t> maskWith(uint32_t w, uint32_t h, std::initializer_list<std::pair<uint32_t, uint32_t>> pixels) {
  std::vector<uint8_t> mask(size_t(w) * h, 0);
  for (const auto& [x, y] : pixels) mask[size_t(y) * w + x] = 1;
  return mask;
}

TEST(ImageCompare, IdenticalMasksAgreeFully) {
  const auto a = maskWith(10, 8, {{1, 1}, {2, 1}, {7, 6}});
  const CoverageComparison c = compareCoverage(a, a, 10, 8);
  EXPECT_EQ(c.covered_a, 3u);
  EXPECT_EQ(c.covered_b, 3u);
  EXPECT_EQ(c.covered_both, 3u);
  EXPECT_EQ(c.agreement, 1.0);
  EXPECT_EQ(c.maxDistance(), 0.0);
  EXPECT_NE(c.summary().find("agreement 1.0000"), std::string::npos) << c.summary();
  EXPECT_EQ(c.summary().find('\n'), std::string::npos);
}

TEST(ImageCompare, ShiftedPixelsGiveTheExpectedNumbers) {
  // One pixel moved two columns: nothing in common, 2 px either way.
  CoverageComparison c = compareCoverage(maskWith(10, 10, {{3, 4}}), maskWith(10, 10, {{5, 4}}), 10, 10);
  EXPECT_EQ(c.covered_both, 0u);
  EXPECT_EQ(c.agreement, 0.0);
  EXPECT_EQ(c.max_distance_a_to_b, 2.0);
  EXPECT_EQ(c.max_distance_b_to_a, 2.0);
  // A 3-4-5 move.
  c = compareCoverage(maskWith(10, 10, {{0, 0}}), maskWith(10, 10, {{3, 4}}), 10, 10);
  EXPECT_EQ(c.maxDistance(), 5.0);
  // A row of five shifted right by one: 4 shared of 6, 1 px each way.
  const auto a = maskWith(10, 5, {{2, 2}, {3, 2}, {4, 2}, {5, 2}, {6, 2}});
  const auto b = maskWith(10, 5, {{3, 2}, {4, 2}, {5, 2}, {6, 2}, {7, 2}});
  c = compareCoverage(a, b, 10, 5);
  EXPECT_EQ(c.covered_both, 4u);
  EXPECT_DOUBLE_EQ(c.agreement, 4.0 / 6.0);
  EXPECT_EQ(c.max_distance_a_to_b, 1.0);
  EXPECT_EQ(c.max_distance_b_to_a, 1.0);
  // B has an extra pixel far from A: only B->A grows.
  const auto b2 = maskWith(10, 5, {{2, 2}, {3, 2}, {4, 2}, {5, 2}, {6, 2}, {9, 4}});
  c = compareCoverage(a, b2, 10, 5);
  EXPECT_EQ(c.max_distance_a_to_b, 0.0);
  EXPECT_DOUBLE_EQ(c.max_distance_b_to_a, std::sqrt(9.0 + 4.0));
  EXPECT_DOUBLE_EQ(c.agreement, 5.0 / 6.0);
}

TEST(ImageCompare, EmptyAgainstNonEmptyIsInfinitelyFar) {
  const auto empty = maskWith(6, 6, {});
  const auto one = maskWith(6, 6, {{2, 3}});
  CoverageComparison c = compareCoverage(one, empty, 6, 6);
  EXPECT_EQ(c.agreement, 0.0);
  EXPECT_TRUE(std::isinf(c.max_distance_a_to_b));
  EXPECT_EQ(c.max_distance_b_to_a, 0.0);
  EXPECT_TRUE(std::isinf(c.maxDistance()));
  c = compareCoverage(empty, empty, 6, 6);
  EXPECT_EQ(c.agreement, 1.0);
  EXPECT_EQ(c.maxDistance(), 0.0);
  EXPECT_THROW(compareCoverage(one, maskWith(6, 5, {}), 6, 6), Error);
}

TEST(ImageCompare, DistanceTransformEqualsBruteForce) {
  std::mt19937 rng(11);
  for (int round = 0; round < 20; ++round) {
    const uint32_t w = 1 + rng() % 40, h = 1 + rng() % 30;
    const double density = (rng() % 100) / 400.0;
    std::vector<uint8_t> mask(size_t(w) * h);
    std::bernoulli_distribution on(density);
    for (auto& m : mask) m = on(rng);
    const std::vector<double> got = squaredDistanceToCovered(mask, w, h);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        double best = std::numeric_limits<double>::infinity();
        for (uint32_t v = 0; v < h; ++v)
          for (uint32_t u = 0; u < w; ++u)
            if (mask[size_t(v) * w + u]) {
              const double dx = double(x) - u, dy = double(y) - v;
              best = std::min(best, dx * dx + dy * dy);
            }
        ASSERT_EQ(got[size_t(y) * w + x], best) << w << "x" << h << " at " << x << "," << y;
      }
  }
}

}  // namespace
}  // namespace fibscope

namespace fibscope {
namespace {

TEST(VisibilityLayout, FourByTwoBlocksMapEveryPixelToItsOwnKeyInsideThePaddedBuffer) {
  for (const auto& [w, h] : {std::pair<uint32_t, uint32_t>{1, 1}, {4, 2}, {5, 3}, {75, 41}, {1920, 1080}}) {
    const uint32_t keys = shader::visibilityKeyCount(w, h);
    EXPECT_EQ(keys, ((w + 3) / 4 * 4) * ((h + 1) / 2 * 2)) << w << " x " << h;
    std::vector<uint8_t> used(keys, 0);
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        const uint32_t i = shader::visibilityIndex(x, y, w);
        ASSERT_LT(i, keys) << x << ", " << y << " of " << w << " x " << h;
        ASSERT_EQ(used[i]++, 0) << "two pixels share key " << i;
        // A block of 4 x 2 pixels is one 64-byte line (8 keys, aligned).
        EXPECT_EQ(i / 8, shader::visibilityIndex(x & ~3u, y & ~1u, w) / 8);
      }
  }
}

}  // namespace
}  // namespace fibscope

namespace fibscope {
namespace {

TEST(PointSample, theSameStreamGivesTheSameSampleInAnyChunksAndStaysWithinItsLimit) {
  const Tractogram all = test::smallTractogram(400, 9);  // ~12 k points
  ASSERT_GT(all.pointCount(), 10000u);
  PointSample whole(1000);
  whole.add(all);
  // The same points in chunks of a few streamlines, as a streamed read.
  PointSample chunked(1000);
  for (size_t first = 0; first < all.streamlineCount(); first += 7) {
    Tractogram chunk;
    for (size_t s = first; s < std::min(first + 7, all.streamlineCount()); ++s)
      chunk.addStreamline(all.point(all.offsets[s]), all.pointsIn(s));
    chunked.add(chunk);
  }
  const std::vector<Vec3d> a = whole.points(), b = chunked.points();
  EXPECT_EQ(a, b);
  EXPECT_GE(a.size(), 500u);
  EXPECT_LE(a.size(), 1000u);
  // The first point of the stream is always kept.
  const float* p = all.point(0);
  EXPECT_EQ(a[0], (Vec3d{p[0], p[1], p[2]}));
  EXPECT_EQ(samplePoints(all, 500), a);
}

}  // namespace
}  // namespace fibscope
