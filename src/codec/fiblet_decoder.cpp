#include "codec/fiblet_decoder.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "core/error.h"

namespace fibscope {

using shader::FibletTransform;
using shader::vec3;

vec3 decodeDirection(uint32_t code, double alpha) {
  const double u = (double(code >> 4 & 15u) + 0.5) / 8.0 - 1.0;
  const double v = (double(code & 15u) + 0.5) / 8.0 - 1.0;
  const double x = (u + v) / 2, y = (u - v) / 2, z = 1.0 - std::max(std::fabs(u), std::fabs(v));
  const double norm = std::sqrt(x * x + y * y + z * z);
  const double theta_h = std::acos(std::clamp(z / norm, -1.0, 1.0));
  const double phi = std::atan2(y, x);
  const double theta = theta_h * alpha / (std::numbers::pi / 2);
  return vec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
}

FibletDirectionTable buildDirectionTable(float alpha) {
  FibletDirectionTable table;
  for (uint32_t code = 0; code < shader::kFibletCodeCount; ++code)
    table[code] = shader::vec4(decodeDirection(code, double(alpha)), 0.0f);
  return table;
}

std::string validateFiblets(const EncodedFiblets& f, const CodecParams& params) {
  const uint32_t n = params.points_per_fiblet;
  if (f.record_bytes != params.recordBytes())
    return "record size " + std::to_string(f.record_bytes) + " bytes, expected " + std::to_string(params.recordBytes());
  if (f.bytes.size() % f.record_bytes != 0)
    return "record bytes " + std::to_string(f.bytes.size()) + " not a multiple of the record size";
  if (f.fiber_first_fiblet.size() != f.fiber_points.size())
    return "fiber tables disagree: " + std::to_string(f.fiber_first_fiblet.size()) + " first-fiblet entries, " +
           std::to_string(f.fiber_points.size()) + " lengths";
  const uint64_t count = f.fibletCount();
  const uint64_t end = f.fiblet_base + count;
  uint64_t expected_first = f.fiblet_base;
  for (size_t fiber = 0; fiber < f.fiberCount(); ++fiber) {
    const uint64_t first = f.fiber_first_fiblet[fiber];
    const uint64_t last = fiber + 1 < f.fiberCount() ? f.fiber_first_fiblet[fiber + 1] : end;
    const std::string where = "fiber " + std::to_string(fiber) + ": ";
    if (first != expected_first || last < first || last > end)
      return where + "first fiblet " + std::to_string(first) + " out of order (expected " +
             std::to_string(expected_first) + ", next " + std::to_string(last) + ", records end at " +
             std::to_string(end) + ")";
    if ((last == first) != (f.fiber_points[fiber] == 0))
      return where + std::to_string(f.fiber_points[fiber]) + " points in " + std::to_string(last - first) + " fiblets";
    uint64_t points = 0;
    for (uint64_t i = first; i < last; ++i) {
      const uint8_t flags = f.record(size_t(i - f.fiblet_base))[shader::fibletFlagsByte(n)];
      const uint32_t c = shader::fibletCount(flags);
      const std::string at = "fiblet " + std::to_string(i) + ": ";
      if (c < 1 || c > n) return at + "point count " + std::to_string(c) + " outside [1, " + std::to_string(n) + "]";
      if (((flags & shader::kFibletFlagBegins) != 0) != (i == first))
        return at + "begins-fiber flag " + std::to_string(flags & 1) + " where " + (i == first ? "1" : "0") +
               " expected";
      if (((flags & shader::kFibletFlagEnds) != 0) != (i + 1 == last))
        return at + "ends-fiber flag wrong for " + where.substr(0, where.size() - 2);
      points += c;
    }
    if (points != f.fiber_points[fiber])
      return where + "fiblets hold " + std::to_string(points) + " points, table says " +
             std::to_string(f.fiber_points[fiber]);
    expected_first = last;
  }
  if (expected_first != end) return std::to_string(end - expected_first) + " fiblets after the last fiber";
  return "";
}

FibletDecoder::FibletDecoder(const CodecParams& params) : params_(params) {
  validateCodecParams(params);
  mm_per_unit_ = 1.0 / double(params.scale);
  v_ = vec3(params.v[0], params.v[1], params.v[2]);
  table_ = buildDirectionTable(params.alpha);
  for (uint32_t code = 0; code < shader::kFibletCodeCount; ++code) {
    const shader::vec4& d = table_[code];
    local_[code] = shader::fibletLocalTransform(vec3(d.x, d.y, d.z), v_, params.delta);
    local4_[code] = toFrame4(local_[code]);
  }
}

namespace {

vec3 recordPoint(const uint8_t* record, int which) {
  float c[3];
  for (int i = 0; i < 3; ++i) {
    const uint8_t* b = record + 6 * which + 2 * i;
    c[i] = shader::fibletDequantize(uint32_t(b[0]) | uint32_t(b[1]) << 8);
  }
  return vec3(c[0], c[1], c[2]);
}

void store(float* xyz, uint32_t k, vec3 p) {
  xyz[3 * k] = p.x;
  xyz[3 * k + 1] = p.y;
  xyz[3 * k + 2] = p.z;
}

}  // namespace

uint32_t FibletDecoder::decodeSequential(const uint8_t* record, float* xyz) const {
  const uint32_t n = params_.points_per_fiblet;
  const uint32_t count = shader::fibletCount(record[shader::fibletFlagsByte(n)]);
  if (count < 1 || count > n) return 0;
  const vec3 p0 = recordPoint(record, 0);
  store(xyz, 0, p0);
  if (count == 1) return 1;
  const vec3 p1 = recordPoint(record, 1);
  store(xyz, 1, p1);
  // Frame4: the operations of fibletCompose lane by lane (bit-identical,
  // tested), about twice as fast as scalar vec3s.
  Frame4 w = toFrame4(shader::fibletInitialTransform(p0, p1, v_));
  for (uint32_t k = 2; k < count; ++k) {
    w = compose4(w, local4_[record[shader::fibletCodeByte(k)]]);
    store(xyz, k, toVec3(w.t));
  }
  return count;
}

uint32_t FibletDecoder::decodeScan(const uint8_t* record, float* xyz) const {
  const uint32_t n = params_.points_per_fiblet;
  const uint32_t count = shader::fibletCount(record[shader::fibletFlagsByte(n)]);
  if (count < 1 || count > n) return 0;
  const vec3 p0 = recordPoint(record, 0);
  store(xyz, 0, p0);
  if (count == 1) return 1;
  // Lane i holds W_1 (i = 0) or L_{i+1}; one lane per point 1..count-1.
  const uint32_t lanes = count - 1;
  std::array<Frame4, shader::kFibletMaxPoints> lane, previous;
  lane[0] = toFrame4(shader::fibletInitialTransform(p0, recordPoint(record, 1), v_));
  for (uint32_t i = 1; i < lanes; ++i) lane[i] = local4_[record[shader::fibletCodeByte(i + 1)]];
  // Hillis-Steele: every lane reads the values of the previous step (the
  // GPU's barrier between steps), lane i >= offset combines with i - offset.
  for (uint32_t offset = 1; offset < lanes; offset *= 2) {
    std::copy(lane.begin(), lane.begin() + lanes, previous.begin());
    for (uint32_t i = offset; i < lanes; ++i) lane[i] = compose4(previous[i - offset], previous[i]);
  }
  for (uint32_t i = 0; i < lanes; ++i) store(xyz, i + 1, toVec3(lane[i].t));
  return count;
}

Tractogram FibletDecoder::decodeAll(const EncodedFiblets& fiblets, DecodeOrder order) const {
  if (const std::string problem = validateFiblets(fiblets, params_); !problem.empty()) fail("fiblets", problem);
  Tractogram out;
  out.positions.reserve(3 *
                        size_t(std::accumulate(fiblets.fiber_points.begin(), fiblets.fiber_points.end(), uint64_t(0))));
  out.offsets.reserve(fiblets.fiberCount() + 1);
  std::array<float, 3 * shader::kFibletMaxPoints> xyz;
  for (size_t i = 0; i < fiblets.fibletCount(); ++i) {
    const uint8_t* record = fiblets.record(i);
    const uint32_t count = decode(record, xyz.data(), order);
    for (uint32_t k = 0; k < count; ++k) {
      const auto w = toWorld(&xyz[3 * k]);
      for (int c = 0; c < 3; ++c) out.positions.push_back(float(w[c]));
    }
  }
  // validateFiblets checked that the records hold exactly these counts.
  for (uint32_t p : fiblets.fiber_points) out.offsets.push_back(out.offsets.back() + p);
  return out;
}

}  // namespace fibscope
