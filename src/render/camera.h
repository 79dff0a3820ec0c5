// Cameras in world space (RAS+ mm) and their Vulkan matrices.
//
// Conventions (the GPU pipelines and the CPU reference rasteriser share
// them; shaders/shared/camera.h states them for the shaders):
//   - right-handed view space looking down -z, x to the right of the image,
//     y up in the image;
//   - clip depth z_clip / w_clip in [0, 1], near plane -> 0, far -> 1;
//   - framebuffer y points DOWN: y_ndc = -1 is the top row of the image
//     (the projection matrix flips y, the viewport is the plain one);
//   - window coordinates x_w = (x_ndc + 1) * width / 2,
//     y_w = (y_ndc + 1) * height / 2; pixel (px, py) has its centre at
//     (px + 0.5, py + 0.5);
//   - matrices are column-major: m[4 * column + row].
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/tractogram.h"
#include "shared/camera.h"

namespace fibscope {

using Vec3d = std::array<double, 3>;
using Mat4 = std::array<float, 16>;  // column-major: m[4 * column + row]

struct Camera {
  Vec3d eye = {0, 0, 100};  // world mm
  Vec3d target = {0, 0, 0};
  Vec3d up = {0, 1, 0};     // need not be orthogonal to the view direction, must not be parallel to it
  double fov_y_deg = 30.0;  // vertical field of view
  double near_mm = 1.0;     // view-space distances of the clip planes, 0 < near < far
  double far_mm = 1000.0;
  uint32_t width = 512;     // px
  uint32_t height = 512;
};

// Throws Error ("camera: ...", one line) when the camera cannot make
// matrices: eye == target, up parallel to the view direction, fov outside
// (0, 180), near <= 0 or far <= near, or an empty image.
void validateCamera(const Camera& camera);

// World -> view: eye at the origin, looking down -z, up projected to +y.
Mat4 viewMatrix(const Camera& camera);
// View -> clip, Vulkan depth [0, 1] and y down (see above).
Mat4 projectionMatrix(const Camera& camera);
// projection * view.
Mat4 viewProjection(const Camera& camera);

// The same matrices in double precision (the reference rasteriser uses these).
std::array<double, 16> viewMatrixD(const Camera& camera);
std::array<double, 16> projectionMatrixD(const Camera& camera);
std::array<double, 16> viewProjectionD(const Camera& camera);

// The shader-side block (shaders/shared/camera.h) for this camera.
// `clip_planes`: world (n, d) planes (render/clip_planes.h), at most
// shader::kMaxFrameClipPlanes; the block gets them and their clip-space form.
shader::CameraBlock makeCameraBlock(const Camera& camera, float line_width_px,
                                    const std::vector<std::array<double, 4>>& clip_planes = {});

// Axis-aligned box in world mm; empty when min > max.
struct Bounds {
  Vec3d min = {0, 0, 0};
  Vec3d max = {0, 0, 0};
};
// Bounds of every point; a tractogram without points gives a box of size 0
// at the origin.
Bounds tractogramBounds(const Tractogram& tractogram);
// The box's 8 corners (bit k of the index picks max on axis k).
std::array<Vec3d, 8> boundsCorners(const Bounds& bounds);
// The smallest box holding both.
Bounds boundsUnion(const Bounds& a, const Bounds& b);
// Radius of the box's bounding sphere (half its diagonal), at least 1 mm:
// what fitCamera frames.
double boundingRadius(const Bounds& bounds);

// The camera with near and far widened (never narrowed) so that the
// points in front of the eye lie between them with a 1 % margin (near not
// below far / 1000): cameras are framed on one box (a tractogram, the
// models visible when the last came in), and an anatomical slice of a
// larger head, or a model shown later, would be cut by the far or near
// plane.
Camera enclosingDepthRange(Camera camera, std::span<const Vec3d> points);

// Places the eye on the ray from the box centre along `direction` (need not
// be unit), looking at the centre with `up`, far enough that the box's
// bounding sphere fits in both the vertical and the horizontal field of view
// when distance_factor is 1 (larger: farther away). Near and far enclose the
// bounding sphere with a 1% margin, so no point of the box is clipped (near
// is kept at a small positive fraction of the distance when the eye is
// inside the sphere).
Camera fitCamera(const Bounds& bounds, Vec3d direction, Vec3d up, uint32_t width, uint32_t height,
                 double distance_factor = 1.0, double fov_y_deg = 30.0);

// Orbit around the box centre: azimuth in the axial plane from +x (right)
// towards +y (anterior), elevation towards +z (superior), both in degrees.
// Up is the direction of increasing elevation, so it stays continuous over
// the poles: (0, 0) looks from the right with superior up.
Camera orbitCamera(const Bounds& bounds, double azimuth_deg, double elevation_deg, uint32_t width,
                   uint32_t height, double distance_factor = 1.0, double fov_y_deg = 30.0);

// The three standard views, fitted to the box:
//   sagittal: eye on +x (the subject's right) looking towards -x, up +z:
//             anterior to the image's right, superior up;
//   coronal:  eye on +y (anterior, facing the subject) looking towards -y,
//             up +z: the subject's right on the image's LEFT (radiological),
//             superior up;
//   axial:    eye on +z (superior, looking down on the head) towards -z,
//             up +y: anterior up, the subject's right on the image's RIGHT
//             (seen from above; radiological axial would be seen from below).
enum class StandardView { Sagittal, Coronal, Axial };
Camera standardView(const Bounds& bounds, StandardView view, uint32_t width, uint32_t height,
                    double distance_factor = 1.0, double fov_y_deg = 30.0);

// The closest camera make(factor) (factor in (0, 2], e.g. an orbitCamera's
// distance factor; 1 fits the box's bounding sphere, which leaves a
// tractogram much smaller on screen than the window) for which every one of
// `points` (world mm: a sample of the tractogram's points, or a box's
// corners) lies in front of the near plane and within `margin` of the image
// centre in normalised device coordinates (0.9: a 5 % border each side).
Camera snugCamera(std::span<const Vec3d> points, const std::function<Camera(double factor)>& make,
                  double margin = 0.9);
// A sample of a stream of points, to frame a view (snugCamera): every
// stride-th point (by index over the whole stream; non-finite ones left
// out), the stride doubling whenever more than `limit` are kept. The same
// points give the same sample however they arrive in chunks, so a file
// read once in chunks (render's streamed upload) and read whole (the
// baselines, the viewer) frame the same picture.
class PointSample {
 public:
  explicit PointSample(size_t limit = 8192) : limit_(limit < 2 ? 2 : limit) {}
  void add(const Tractogram& chunk);
  // Between limit / 2 and limit points once there are that many.
  std::vector<Vec3d> points() const;

 private:
  size_t limit_;
  uint64_t stride_ = 1, seen_ = 0;
  std::vector<std::pair<uint64_t, Vec3d>> kept_;  // (index in the stream, point)
};

// PointSample of the whole tractogram with limit 2 * count: about `count`
// to 2 * count of its points.
std::vector<Vec3d> samplePoints(const Tractogram& tractogram, size_t count = 4096);

}  // namespace fibscope
