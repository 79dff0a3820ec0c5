#include "render/reference_raster.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <thread>
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

// The image's scanlines (each row after filter byte 0, none) as raw
// deflate data, in bands of rows compressed on every core: each band is an
// independent stream that ends on a byte boundary without the final bit
// (Z_SYNC_FLUSH; the last band Z_FINISH), so the bands joined after a zlib
// header form one valid zlib stream (the method of pigz); the Adler-32 of
// the whole is combined from the bands'. A band's matches never reach into
// the band before, which costs a little compression at each seam. Rows go
// to zlib straight from `rgba` (no copy of the image to touch first).
// A 1920x1080 frame: ~0.09 s on one core, about half on two.
struct DeflatedBand {
  std::unique_ptr<uint8_t[]> packed;  // not value-initialised: only the pages written are touched
  size_t packed_bytes = 0;
  uLong adler = 0;
  uLong raw_bytes = 0;
  bool ok = false;
};

std::vector<DeflatedBand> deflateScanlines(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  const size_t row_bytes = size_t(width) * 4;
  const unsigned bands = std::clamp<unsigned>(height / 64, 1, std::max(1u, std::thread::hardware_concurrency()));
  std::vector<DeflatedBand> out(bands);
  auto deflateBand = [&](unsigned b) {
    const uint32_t y0 = uint32_t(uint64_t(height) * b / bands), y1 = uint32_t(uint64_t(height) * (b + 1) / bands);
    const uint64_t raw_size = uint64_t(row_bytes + 1) * (y1 - y0);
    if (row_bytes > 0xFFFFFFFFu || raw_size > 0xFFFFFFFFu) return;  // zlib counts in 32 bits: reported by the caller
    DeflatedBand& band = out[b];
    z_stream z{};
    if (deflateInit2(&z, Z_BEST_SPEED, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) return;
    const size_t capacity = deflateBound(&z, uLong(raw_size)) + 64;  // + the empty stored block of the flush
    band.packed.reset(new uint8_t[capacity]);
    z.next_out = band.packed.get();
    z.avail_out = uInt(capacity);
    Bytef filter = 0;
    uLong adler = adler32(0L, Z_NULL, 0);
    bool ok = true;
    for (uint32_t y = y0; y < y1 && ok; ++y) {
      Bytef* row = const_cast<Bytef*>(rgba.data() + size_t(y) * row_bytes);  // zlib only reads next_in
      adler = adler32(adler32(adler, &filter, 1), row, uInt(row_bytes));
      z.next_in = &filter;
      z.avail_in = 1;
      ok = deflate(&z, Z_NO_FLUSH) == Z_OK && z.avail_in == 0;
      z.next_in = row;
      z.avail_in = uInt(row_bytes);
      ok = ok && deflate(&z, Z_NO_FLUSH) == Z_OK && z.avail_in == 0;
    }
    const bool last = b + 1 == bands;
    const int status = ok ? deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH) : Z_STREAM_ERROR;
    band.ok = last ? status == Z_STREAM_END : status == Z_OK;
    band.packed_bytes = z.total_out;
    deflateEnd(&z);
    band.adler = adler;
    band.raw_bytes = uLong(raw_size);
  };
  std::vector<std::jthread> helpers;
  for (unsigned b = 1; b < bands; ++b) helpers.emplace_back(deflateBand, b);
  deflateBand(0);
  helpers.clear();  // joins
  return out;
}

std::vector<uint8_t> bigEndian(uint32_t v) { return {uint8_t(v >> 24), uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)}; }

}  // namespace

void writePngRgba(const std::string& path, uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba) {
  if (width == 0 || height == 0 || width > 0x7FFFFFFFu || height > 0x7FFFFFFFu)
    fail(path, "PNG size must be 1 to 2^31 - 1 pixels per side, got " + std::to_string(width) + " x " +
                   std::to_string(height));
  const size_t row_bytes = size_t(width) * 4;
  if (rgba.size() != row_bytes * height)
    fail(path, "PNG: expected " + std::to_string(row_bytes * height) + " RGBA bytes, got " +
                   std::to_string(rgba.size()));
  const std::vector<DeflatedBand> bands = deflateScanlines(width, height, rgba);
  // IDAT: zlib header (deflate, 32 KiB window, fastest), the bands, Adler-32.
  const std::vector<uint8_t> zlib_header = {0x78, 0x01};
  uint64_t idat_bytes = zlib_header.size() + 4;
  uLong adler = adler32(0L, Z_NULL, 0);
  for (const DeflatedBand& band : bands) {
    if (!band.ok) fail(path, "PNG: zlib compression failed (image of " + std::to_string(width) + " x " +
                                 std::to_string(height) + " px)");
    idat_bytes += band.packed_bytes;
    adler = adler32_combine(adler, band.adler, z_off_t(band.raw_bytes));
  }
  if (idat_bytes > 0x7FFFFFFFu) fail(path, "PNG: compressed image over 2 GiB");
  const std::vector<uint8_t> adler_bytes = bigEndian(uint32_t(adler));

  std::vector<uint8_t> head = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<uint8_t> ihdr;
  putU32(ihdr, width);
  putU32(ihdr, height);
  ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});  // 8 bits, colour type 6 (RGBA), deflate, no filter, no interlace
  putChunk(head, "IHDR", ihdr);
  putU32(head, uint32_t(idat_bytes));
  const size_t type_at = head.size();
  head.insert(head.end(), {'I', 'D', 'A', 'T'});
  head.insert(head.end(), zlib_header.begin(), zlib_header.end());
  // The chunk's CRC runs over its type and data, written in pieces.
  uLong crc = crc32(0L, head.data() + type_at, uInt(head.size() - type_at));
  OutputFile file(path, true);
  file.write(head.data(), head.size());
  for (const DeflatedBand& band : bands) {
    crc = crc32(crc, band.packed.get(), uInt(band.packed_bytes));
    file.write(band.packed.get(), band.packed_bytes);
  }
  crc = crc32(crc, adler_bytes.data(), uInt(adler_bytes.size()));
  std::vector<uint8_t> tail = adler_bytes;
  putU32(tail, uint32_t(crc));
  putChunk(tail, "IEND", {});
  file.write(tail.data(), tail.size());
  file.commit();
}

}  // namespace fibscope
