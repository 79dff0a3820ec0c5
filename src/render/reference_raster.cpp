#include "render/reference_raster.h"

#include <bit>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "select/cut_mesh.h"
#include "shared/cut_mesh.h"

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <string>

#include "core/error.h"

namespace fibscope {

ReferenceFrame::ReferenceFrame(uint32_t w, uint32_t h)
    : width(w),
      height(h),
      depth(size_t(w) * h, kEmptyDepth),
      fiber(size_t(w) * h, kNoFiber),
      point(size_t(w) * h, 0),
      tangent(size_t(w) * h, std::array<float, 3>{0, 0, 0}),
      fragments(size_t(w) * h, 0) {}

size_t ReferenceFrame::coveredPixels() const {
  return size_t(std::count_if(fiber.begin(), fiber.end(), [](uint32_t f) { return f != kNoFiber; }));
}

std::vector<uint8_t> ReferenceFrame::coverageMask() const {
  std::vector<uint8_t> mask(fiber.size());
  for (size_t i = 0; i < fiber.size(); ++i) mask[i] = fiber[i] != kNoFiber ? 1 : 0;
  return mask;
}

void rasterizeWindowSegment(ReferenceFrame& frame, const WindowVertex& a, const WindowVertex& b,
                            uint32_t fiber, uint32_t point, const std::array<float, 3>& tangent,
                            float line_width_px) {
  if (frame.width == 0 || frame.height == 0) return;
  if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(b.x) || !std::isfinite(b.y) ||
      !std::isfinite(a.depth) || !std::isfinite(b.depth))
    return;
  const double radius = double(line_width_px) / 2;
  // Pixel px is a candidate when its centre px + 0.5 lies in
  // [min - radius, max + radius]; clamp in double before converting, the
  // ends of a segment close to the near plane can be far off screen.
  const double x_lo = std::max(std::ceil(std::min(a.x, b.x) - radius - 0.5), 0.0);
  const double x_hi = std::min(std::floor(std::max(a.x, b.x) + radius - 0.5), double(frame.width) - 1);
  const double y_lo = std::max(std::ceil(std::min(a.y, b.y) - radius - 0.5), 0.0);
  const double y_hi = std::min(std::floor(std::max(a.y, b.y) + radius - 0.5), double(frame.height) - 1);
  if (x_lo > x_hi || y_lo > y_hi) return;

  const double dx = b.x - a.x, dy = b.y - a.y;
  const double length2 = dx * dx + dy * dy;
  const double radius2 = radius * radius;
  for (uint32_t py = uint32_t(y_lo); py <= uint32_t(y_hi); ++py) {
    const double cy = py + 0.5;
    for (uint32_t px = uint32_t(x_lo); px <= uint32_t(x_hi); ++px) {
      const double cx = px + 0.5;
      double t = 0;
      if (length2 > 0) t = std::clamp(((cx - a.x) * dx + (cy - a.y) * dy) / length2, 0.0, 1.0);
      const double ex = cx - (a.x + t * dx), ey = cy - (a.y + t * dy);
      if (ex * ex + ey * ey > radius2) continue;
      const double depth = a.depth + t * (b.depth - a.depth);
      if (depth > 1.0) continue;  // beyond the far plane
      const float d = float(depth);
      const size_t i = frame.index(px, py);
      bool cut = false;
      for (const ReferenceMeshCut& m : frame.mesh_cuts)
        cut |= shader::cutInside(std::bit_cast<uint32_t>(m.front[i]), std::bit_cast<uint32_t>(m.back[i]), d) ==
               m.cull_inside;
      if (cut) continue;
      ++frame.fragments[i];
      const bool wins = d < frame.depth[i] ||
                        (d == frame.depth[i] && (fiber < frame.fiber[i] ||
                                                 (fiber == frame.fiber[i] && point < frame.point[i])));
      if (!wins) continue;
      frame.depth[i] = d;
      frame.fiber[i] = fiber;
      frame.point[i] = point;
      frame.tangent[i] = tangent;
    }
  }
}

namespace {

using Clip = std::array<double, 4>;

Clip toClip(const std::array<double, 16>& m, const double* p) {
  Clip c{};
  for (int r = 0; r < 4; ++r) c[r] = m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r];
  return c;
}

// Step 2b: the part of world segment a -> b on the kept side of every
// plane (n.p + d >= 0), cut where it crosses one, in world space; false
// when nothing is left.
bool clipToPlanes(std::array<double, 3>& a, std::array<double, 3>& b,
                  const std::vector<std::array<double, 4>>& planes) {
  for (const auto& q : planes) {
    const double da = q[0] * a[0] + q[1] * a[1] + q[2] * a[2] + q[3];
    const double db = q[0] * b[0] + q[1] * b[1] + q[2] * b[2] + q[3];
    if (da < 0 && db < 0) return false;
    if (da < 0 || db < 0) {
      const double t = da / (da - db);
      std::array<double, 3> cut{};
      for (int k = 0; k < 3; ++k) cut[k] = a[k] + t * (b[k] - a[k]);
      (da < 0 ? a : b) = cut;
    }
  }
  return true;
}

// Step 2: both ends outside the same plane of the frustum.
bool outsideFrustum(const Clip& a, const Clip& b) {
  for (int axis = 0; axis < 2; ++axis) {
    if (a[axis] < -a[3] && b[axis] < -b[3]) return true;
    if (a[axis] > a[3] && b[axis] > b[3]) return true;
  }
  if (a[2] < 0 && b[2] < 0) return true;
  return a[2] > a[3] && b[2] > b[3];
}

WindowVertex toWindow(const Clip& c, uint32_t width, uint32_t height) {
  return {(c[0] / c[3] + 1) * width / 2, (c[1] / c[3] + 1) * height / 2, c[2] / c[3]};
}

}  // namespace

ReferenceFrame rasterizeReference(const Tractogram& tractogram, const Camera& camera, float line_width_px,
                                  const std::vector<std::array<double, 4>>& clip_planes,
                                  const std::vector<ReferenceMeshCut>& mesh_cuts) {
  if (!(line_width_px >= kMinLineWidth && line_width_px <= kMaxLineWidth))
    fail("reference raster", "line width must lie in [1, 4] px, got " + std::to_string(line_width_px));
  if (tractogram.streamlineCount() >= kNoFiber)
    fail("reference raster", "more than 2^32 - 2 streamlines");
  const std::array<double, 16> vp = viewProjectionD(camera);  // validates the camera
  ReferenceFrame frame(camera.width, camera.height);
  frame.mesh_cuts = mesh_cuts;
  for (size_t s = 0; s < tractogram.streamlineCount(); ++s) {
    const size_t first = tractogram.offsets[s], n = tractogram.pointsIn(s);
    if (n > 0xFFFFFFFFu) fail("reference raster", "streamline " + std::to_string(s) + " has more than 2^32 - 1 points");
    for (size_t j = 0; j + 1 < n; ++j) {
      const float* p0 = tractogram.point(first + j);
      const float* p1 = tractogram.point(first + j + 1);
      std::array<double, 3> w0 = {p0[0], p0[1], p0[2]}, w1 = {p1[0], p1[1], p1[2]};
      if (!clipToPlanes(w0, w1, clip_planes)) continue;
      Clip c0 = toClip(vp, w0.data()), c1 = toClip(vp, w1.data());
      if (outsideFrustum(c0, c1)) continue;
      // Step 3: near plane z >= 0; the part behind it is cut off.
      if (c0[2] < 0 || c1[2] < 0) {
        const double t = c0[2] / (c0[2] - c1[2]);  // where z crosses 0, from c0
        Clip cut{};
        for (int k = 0; k < 4; ++k) cut[k] = c0[k] + t * (c1[k] - c0[k]);
        cut[2] = 0;
        (c0[2] < 0 ? c0 : c1) = cut;
      }
      const double tx = double(p1[0]) - p0[0], ty = double(p1[1]) - p0[1], tz = double(p1[2]) - p0[2];
      const double len = std::sqrt(tx * tx + ty * ty + tz * tz);
      std::array<float, 3> tangent = {0, 0, 0};
      if (len > 0) tangent = {float(tx / len), float(ty / len), float(tz / len)};
      rasterizeWindowSegment(frame, toWindow(c0, camera.width, camera.height),
                             toWindow(c1, camera.width, camera.height), uint32_t(s), uint32_t(j), tangent,
                             line_width_px);
    }
  }
  return frame;
}

ReferenceMeshCut referenceMeshCut(const TriangleMesh& mesh, const Camera& camera, bool cull_inside) {
  const std::array<double, 16> vp = viewProjectionD(camera);
  const glm::dmat4 m = glm::make_mat4(vp.data()), inverse = glm::inverse(m);
  ReferenceMeshCut cut;
  cut.cull_inside = cull_inside;
  const size_t pixels = size_t(camera.width) * camera.height;
  cut.front.assign(pixels, kEmptyDepth);
  cut.back.assign(pixels, kEmptyDepth);
  const glm::vec3 eye(camera.eye[0], camera.eye[1], camera.eye[2]);
  for (uint32_t py = 0; py < camera.height; ++py)
    for (uint32_t px = 0; px < camera.width; ++px) {
      const double x = (px + 0.5) / camera.width * 2 - 1, y = (py + 0.5) / camera.height * 2 - 1;
      glm::dvec4 far_point = inverse * glm::dvec4(x, y, 1, 1);
      far_point /= far_point.w;
      const glm::vec3 dir = glm::vec3(glm::dvec3(far_point) - glm::dvec3(eye));
      const size_t i = size_t(py) * camera.width + px;
      for (const MeshHit& hit : rayMeshHits(mesh, eye, dir)) {
        const glm::dvec3 p = glm::dvec3(eye) + double(hit.distance) * glm::normalize(glm::dvec3(dir));
        const glm::dvec4 c = m * glm::dvec4(p, 1);
        const double depth = c.z / c.w;
        if (!(depth >= 0 && depth <= 1)) continue;  // clipped at the near plane or beyond the far one
        float& slot = hit.front ? cut.front[i] : cut.back[i];
        slot = std::min(slot, float(depth));
      }
    }
  return cut;
}

void rasterizeReferenceSpheres(ReferenceFrame& frame, const std::vector<ReferenceSphere>& spheres,
                               const Camera& camera) {
  const std::array<double, 16> vp = viewProjectionD(camera);  // validates the camera
  const std::array<double, 16> view = viewMatrixD(camera), projection = projectionMatrixD(camera);
  if (frame.width != camera.width || frame.height != camera.height)
    fail("reference raster", "the frame is not the camera's size");
  for (const ReferenceSphere& s : spheres)
    if (!(s.radius > 0)) fail("reference raster", "a sphere's radius must be > 0 mm");
  // The view's axes in world space are the rows of its rotation; the eye
  // ray through NDC (x, y) is (x / P00, y / P11, -1) in view space.
  const glm::dvec3 right(view[0], view[4], view[8]), up(view[1], view[5], view[9]), back(view[2], view[6], view[10]);
  const glm::dvec3 eye(camera.eye[0], camera.eye[1], camera.eye[2]);
  auto clipDepth = [&](const glm::dvec3& q) {
    const double z = vp[2] * q.x + vp[6] * q.y + vp[10] * q.z + vp[14];
    const double w = vp[3] * q.x + vp[7] * q.y + vp[11] * q.z + vp[15];
    return w > 0 ? z / w : -1.0;
  };
  for (uint32_t py = 0; py < frame.height; ++py) {
    for (uint32_t px = 0; px < frame.width; ++px) {
      const double x_ndc = (px + 0.5) / frame.width * 2 - 1, y_ndc = (py + 0.5) / frame.height * 2 - 1;
      const glm::dvec3 d = glm::normalize(x_ndc / projection[0] * right + y_ndc / projection[5] * up - back);
      const size_t i = frame.index(px, py);
      for (const ReferenceSphere& s : spheres) {
        const glm::dvec3 c(s.center[0], s.center[1], s.center[2]);
        const glm::dvec3 oc = eye - c;
        const double b = glm::dot(oc, d);
        const double disc = s.radius * s.radius - glm::dot(oc - b * d, oc - b * d);
        if (disc < 0) continue;
        double t = -b - std::sqrt(disc);
        double depth = clipDepth(eye + t * d);
        if (depth < 0) {
          t = -b + std::sqrt(disc);
          depth = clipDepth(eye + t * d);
        }
        if (!(depth >= 0 && depth <= 1) || !(depth < frame.depth[i])) continue;
        const glm::dvec3 n = (eye + t * d - c) / s.radius;
        frame.depth[i] = float(depth);
        frame.fiber[i] = s.id;
        frame.point[i] = 0;
        frame.tangent[i] = {float(n.x), float(n.y), float(n.z)};
        ++frame.fragments[i];
      }
    }
  }
}

std::vector<uint8_t> shadeOrientation(const ReferenceFrame& frame) {
  std::vector<uint8_t> rgba(frame.fiber.size() * 4, 0);
  for (size_t i = 0; i < frame.fiber.size(); ++i) {
    if (frame.fiber[i] != kNoFiber)
      for (int k = 0; k < 3; ++k)
        rgba[4 * i + k] = uint8_t(std::lround(std::clamp(std::fabs(frame.tangent[i][k]), 0.0f, 1.0f) * 255.0f));
    rgba[4 * i + 3] = 255;
  }
  return rgba;
}

}  // namespace fibscope
