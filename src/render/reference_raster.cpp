#include "render/reference_raster.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/output_file.h"

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

Clip toClip(const std::array<double, 16>& m, const float* p) {
  Clip c{};
  for (int r = 0; r < 4; ++r)
    c[r] = m[r] * double(p[0]) + m[4 + r] * double(p[1]) + m[8 + r] * double(p[2]) + m[12 + r];
  return c;
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

ReferenceFrame rasterizeReference(const Tractogram& tractogram, const Camera& camera, float line_width_px) {
  if (!(line_width_px >= kMinLineWidth && line_width_px <= kMaxLineWidth))
    fail("reference raster", "line width must lie in [1, 4] px, got " + std::to_string(line_width_px));
  if (tractogram.streamlineCount() >= kNoFiber)
    fail("reference raster", "more than 2^32 - 2 streamlines");
  const std::array<double, 16> vp = viewProjectionD(camera);  // validates the camera
  ReferenceFrame frame(camera.width, camera.height);
  for (size_t s = 0; s < tractogram.streamlineCount(); ++s) {
    const size_t first = tractogram.offsets[s], n = tractogram.pointsIn(s);
    if (n > 0xFFFFFFFFu) fail("reference raster", "streamline " + std::to_string(s) + " has more than 2^32 - 1 points");
    for (size_t j = 0; j + 1 < n; ++j) {
      const float* p0 = tractogram.point(first + j);
      const float* p1 = tractogram.point(first + j + 1);
      Clip c0 = toClip(vp, p0), c1 = toClip(vp, p1);
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

namespace {

void putU32(std::vector<uint8_t>& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(uint8_t(v >> shift));
}

// A PNG chunk: big-endian length, type, data, CRC-32 of type and data.
void putChunk(std::vector<uint8_t>& out, const char type[4], const std::vector<uint8_t>& data) {
  putU32(out, uint32_t(data.size()));
  const size_t type_at = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  putU32(out, uint32_t(crc32(0L, out.data() + type_at, uInt(4 + data.size()))));
}

}  // namespace

void writePngRgba(const std::string& path, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  if (width == 0 || height == 0 || width > 0x7FFFFFFFu || height > 0x7FFFFFFFu)
    fail(path, "PNG size must be 1 to 2^31 - 1 pixels per side, got " + std::to_string(width) + " x " +
                   std::to_string(height));
  const size_t row_bytes = size_t(width) * 4;
  if (rgba.size() != row_bytes * height)
    fail(path, "PNG: expected " + std::to_string(row_bytes * height) + " RGBA bytes, got " +
                   std::to_string(rgba.size()));
  // Scanlines, each preceded by filter type 0 (none).
  std::vector<uint8_t> raw;
  raw.reserve((row_bytes + 1) * height);
  for (uint32_t y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.insert(raw.end(), rgba.begin() + std::ptrdiff_t(y * row_bytes), rgba.begin() + std::ptrdiff_t((y + 1) * row_bytes));
  }
  uLongf packed_size = compressBound(uLong(raw.size()));
  std::vector<uint8_t> packed(packed_size);
  if (compress2(packed.data(), &packed_size, raw.data(), uLong(raw.size()), Z_BEST_SPEED) != Z_OK)
    fail(path, "PNG: zlib compression failed");
  packed.resize(packed_size);

  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<uint8_t> ihdr;
  putU32(ihdr, width);
  putU32(ihdr, height);
  ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});  // 8 bits, colour type 6 (RGBA), deflate, no filter, no interlace
  putChunk(png, "IHDR", ihdr);
  putChunk(png, "IDAT", packed);
  putChunk(png, "IEND", {});
  OutputFile file(path, true);
  file.write(png.data(), png.size());
  file.commit();
}

}  // namespace fibscope
