#include "codec/fiblet_encoder.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <limits>
#include <numbers>
#include <string>

#include "core/error.h"

namespace fibscope {

using shader::FibletTransform;
using shader::vec3;

void EncodeReport::merge(const EncodeReport& o) {
  fibers += o.fibers;
  points += o.points;
  fiblets += o.fiblets;
  angle_splits += o.angle_splits;
  step_splits += o.step_splits;
  error_splits += o.error_splits;
  single_point_fibers += o.single_point_fibers;
  two_point_fibers += o.two_point_fibers;
  clamped_points += o.clamped_points;
  min_signed_cos2 = std::min(min_signed_cos2, o.min_signed_cos2);
}

double EncodeReport::maxTurnDegrees() const {
  const double c = min_signed_cos2 >= 0 ? std::sqrt(min_signed_cos2) : -std::sqrt(-min_signed_cos2);
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

float FibletEncoder::search(const glm::dvec3& local, uint32_t& code) const {
  const auto lx = float(local[0]), ly = float(local[1]), lz = float(local[2]);
  if (options_.search_size == 2) {
    // The default: the 2 x 2 cells nearest the goal's direction, one
    // four-lane vector (candidates in row-major order).
    const uint32_t origin = quantizer_.block2(local[0], local[1], local[2]);
    const Block& b = blocks_[origin];
    const V4f ex = b.x - splat4(lx), ey = b.y - splat4(ly), ez = b.z - splat4(lz);
    const V4f d2 = ex * ex + ey * ey + ez * ez;
    // The first smallest without branches (its position is data, so
    // branches mispredict): distances are >= 0, so their bits order as
    // integers, and (bits << 2 | position) orders by distance, then by
    // position; integer minimums compile to cmov.
    uint32_t bits[4];
    std::memcpy(bits, &d2, sizeof bits);
    const auto key = [&](int c) { return uint64_t(bits[c]) << 2 | uint64_t(c); };
    const auto least = [](uint64_t x, uint64_t y) { return y < x ? y : x; };
    const int pick = int(least(least(key(0), key(1)), least(key(2), key(3))) & 3u);
    code = origin + uint32_t(pick >> 1) * 16u + uint32_t(pick & 1);
    return d2[pick];
  }
  // Any other block size, one candidate after the other (same distances).
  const int size = options_.search_size;
  const uint32_t origin = blockOrigin(quantizer_.gridFromFormula(local[0], local[1], local[2]), size);
  float best = std::numeric_limits<float>::infinity();
  for (int i = 0; i < size; ++i) {
    for (int j = 0; j < size; ++j) {
      const uint32_t c = origin + uint32_t(16 * i + j);
      const float ex = step_x_[c] - lx, ey = step_y_[c] - ly, ez = step_z_[c] - lz;
      const float e2 = ex * ex + ey * ey + ez * ez;
      if (e2 < best) {
        best = e2;
        code = c;
      }
    }
  }
  return best;
}

namespace {

// The point at p (x, y, z) of a lane's targets.
glm::dvec3 point(const double* p) { return {p[0], p[1], p[2]}; }

}  // namespace

void FibletEncoder::noteTurn(const Lane& lane, size_t j) {
  const double* p = lane.target.data() + 3 * j;
  const glm::dvec3 a = point(p) - point(p - 3), b = point(p + 3) - point(p);
  const double dot = glm::dot(a, b);
  const double a2 = glm::dot(a, a), b2 = glm::dot(b, b);
  if (std::isfinite(dot) && std::isfinite(a2) && std::isfinite(b2)) noteTurn(dot, b2, a2);
}

FibletEncoder::FibletEncoder(const CodecParams& params, const EncodeOptions& options)
    : params_(params),
      options_(options),
      decoder_(params),
      quantizer_(params.alpha, params.delta),
      um2_per_unit2_(std::pow(1000.0 / double(params.scale), 2)) {
  v_ = vec3(params.v[0], params.v[1], params.v[2]);
  const double delta = params.delta;
  len2_lo_ = std::pow((1 - options.step_tolerance) * delta, 2);
  len2_hi_ = std::pow((1 + options.step_tolerance) * delta, 2);
  // A little slack so that a turn of exactly alpha (the largest
  // representable one) is not an exception.
  cos_alpha_ = std::cos(double(params.alpha)) - 1e-6;
  cos2_alpha_ = cos_alpha_ * cos_alpha_;
  max_error2_ = std::pow(options.max_point_error * delta, 2);
  if (options.search_size < 1 || options.search_size > 16) fail("fiblet encoder", "search size outside [1, 16]");
  step_x_.fill(0);
  step_y_.fill(0);
  step_z_.fill(0);
  for (uint32_t c = 0; c < shader::kFibletCodeCount; ++c) {
    const vec3& step = decoder_.localTransform(c).t;
    step_x_[c] = step.x;
    step_y_[c] = step.y;
    step_z_[c] = step.z;
    local4_[c] = toFrame4(decoder_.localTransform(c));
  }
  for (uint32_t o = 0; o < shader::kFibletCodeCount; ++o) {
    // Blocks start at i, j <= 14; other origins are never used (kept zero).
    if ((o >> 4) > 14 || (o & 15u) > 14) continue;
    const uint32_t c[4] = {o, o + 1, o + 16, o + 17};
    blocks_[o] = {V4f{step_x_[c[0]], step_x_[c[1]], step_x_[c[2]], step_x_[c[3]]},
                  V4f{step_y_[c[0]], step_y_[c[1]], step_y_[c[2]], step_y_[c[3]]},
                  V4f{step_z_[c[0]], step_z_[c[1]], step_z_[c[2]], step_z_[c[3]]}};
  }
}

namespace {

// The frame's axes in double (the products and sums in glm::dot's order,
// x + y then + z, as the encoder always did: the encoding stays bit for bit).
glm::dvec3 axis(const vec3& a) { return {a.x, a.y, a.z}; }
glm::dvec3 axis(V4f a) { return {a[0], a[1], a[2]}; }

vec3 toVec3(const double* p) { return vec3(float(p[0]), float(p[1]), float(p[2])); }
vec3 toVec3(const glm::dvec3& p) { return vec3(float(p.x), float(p.y), float(p.z)); }

}  // namespace

void FibletEncoder::startFiber(Lane& lane, const float* xyz, size_t n) {
  if (n > std::numeric_limits<uint32_t>::max()) fail("fiblet encoder", "more than 2^32 points in one fiber");
  ++report_.fibers;
  report_.points += n;
  if (n == 1) ++report_.single_point_fibers;
  if (n == 2) ++report_.two_point_fibers;
  lane.target.resize(3 * n);
  const double tx = params_.translation[0], ty = params_.translation[1], tz = params_.translation[2];
  const double scale = params_.scale;
  double* out = lane.target.data();
  for (size_t i = 0; i < n; ++i, xyz += 3, out += 3) {
    out[0] = (double(xyz[0]) - tx) * scale;
    out[1] = (double(xyz[1]) - ty) * scale;
    out[2] = (double(xyz[2]) - tz) * scale;
  }
  lane.n = n;
  if (meter_) lane.decoded.resize(n);
  lane.first = 0;
  lane.fiber_offset = lane.bytes.size();
  lane.fiber_fiblets = 0;
  lane.active = n > 0;  // an empty fiber has no fiblet
  if (n > 0) startFiblet(lane);
}

void FibletEncoder::measureFiber(const Lane& lane) {
  // A separate pass over the fiber's decoded points: inside the encoding
  // loop the same arithmetic crowded the out-of-order window that overlaps
  // the lanes' frame chains and cost a quarter of the encoder's speed.
  const double* o = lane.target.data();
  for (size_t i = 0; i < lane.n; ++i, o += 3) {
    const V4f p = lane.decoded[i];
    const double e2 = (double(p[0]) - o[0]) * (double(p[0]) - o[0]) + (double(p[1]) - o[1]) * (double(p[1]) - o[1]) +
                      (double(p[2]) - o[2]) * (double(p[2]) - o[2]);
    if (std::isfinite(e2)) meter_->add(std::sqrt(e2 * um2_per_unit2_));
  }
}

void FibletEncoder::startFiblet(Lane& lane) {
  const size_t first = lane.first, n = lane.n;
  lane.base = lane.bytes.size();
  lane.bytes.resize(lane.base + params_.recordBytes(), 0);
  const double* t = lane.target.data();

  // Points 0 and 1, quantised to 16 bits per coordinate.
  vec3 decoded[2];
  for (int which = 0; which < 2; ++which) {
    const size_t index = std::min(first + size_t(which), n - 1);
    float c[3];
    for (int axis = 0; axis < 3; ++axis) {
      const double scaled = t[3 * index + axis] * shader::kFibletQuantMax;
      const bool inside = scaled >= -0.5 && scaled <= shader::kFibletQuantMax + 0.5;  // false for NaN
      if (!inside && axis == 0 && (which == 0 || first + 1 < n)) ++report_.clamped_points;
      const uint32_t q = inside ? uint32_t(std::nearbyint(std::clamp(scaled, 0.0, double(shader::kFibletQuantMax))))
                                : (scaled > 0 ? shader::kFibletQuantMax : 0u);
      lane.bytes[lane.base + 6 * size_t(which) + 2 * size_t(axis)] = uint8_t(q);
      lane.bytes[lane.base + 6 * size_t(which) + 2 * size_t(axis) + 1] = uint8_t(q >> 8);
      c[axis] = shader::fibletDequantize(q);
    }
    decoded[which] = vec3(c[0], c[1], c[2]);
  }
  if (meter_) {
    lane.decoded[first] = toV4f(decoded[0]);
    if (first + 1 < n) lane.decoded[first + 1] = toV4f(decoded[1]);
  }
  // Turns around the join with the previous fiblet, which no fiblet's steps
  // measure (for the report's largest turn).
  if (first >= 2) noteTurn(lane, first - 1);
  if (first >= 1 && first + 1 < n) noteTurn(lane, first);

  lane.count_max = std::min<size_t>(params_.points_per_fiblet, n - first);
  lane.count = std::min<size_t>(lane.count_max, 2);
  lane.k = 2;
  if (lane.count_max >= 3) {
    // The decoder's frame (Frame4: bit-identical to fibletCompose, faster),
    // and (true-frame variant) the frame of the true directions.
    lane.w = toFrame4(shader::fibletInitialTransform(decoded[0], decoded[1], v_));
    if (options_.mode == EncodeMode::TrueFrame)
      lane.truth = shader::fibletInitialTransform(toVec3(t + 3 * first), toVec3(t + 3 * first + 3), v_);
  }
}

bool FibletEncoder::stepFiblet(Lane& lane) {
  const size_t k = lane.k;
  if (k >= lane.count_max) return false;
  const double* here = lane.target.data() + 3 * (lane.first + k);
  const glm::dvec3 seg = point(here) - point(here - 3), prev = point(here - 3) - point(here - 6);
  const double len2 = glm::dot(seg, seg);
  const double plen2 = glm::dot(prev, prev);
  const double turn_dot = glm::dot(seg, prev);
  noteTurn(turn_dot, len2, plen2);
  // Step and turn checks on squared quantities (no sqrt or division per
  // point): |len - delta| <= tol * delta and cos(turn) >= cos(alpha).
  if (!(len2 >= len2_lo_ && len2 <= len2_hi_)) {  // also catches NaN
    ++report_.step_splits;
    return false;
  }
  const double needed = cos_alpha_ >= 0 ? cos2_alpha_ * len2 * plen2 : -cos2_alpha_ * len2 * plen2;
  const double signed_dot2 = turn_dot >= 0 ? turn_dot * turn_dot : -turn_dot * turn_dot;
  if (!(plen2 > 0) || signed_dot2 < needed) {
    ++report_.angle_splits;
    return false;
  }
  Frame4& w = lane.w;
  uint32_t code = 0;
  if (options_.mode == EncodeMode::ClosedLoop) {
    // The original point in the decoded frame. The decoded frame is a
    // rotation (orthonormal to float precision), so the distance of a
    // candidate's decoded point W * L_c.t to the original point equals
    // |L_c.t - local|: the search runs in local coordinates.
    const glm::dvec3 diff = point(here) - glm::dvec3(w.t[0], w.t[1], w.t[2]);
    const glm::dvec3 local(glm::dot(axis(w.c0), diff), glm::dot(axis(w.c1), diff), glm::dot(axis(w.c2), diff));
    const float best = search(local, code);
    if (double(best) > max_error2_) {
      ++report_.error_splits;
      return false;
    }
  } else if (options_.mode == EncodeMode::OpenLoop) {
    const glm::dvec3 local(glm::dot(axis(w.c0), seg), glm::dot(axis(w.c1), seg), glm::dot(axis(w.c2), seg));
    code = encodeDirection(local, params_.alpha);
  } else {
    const glm::dvec3 local(glm::dot(axis(lane.truth.c0), seg), glm::dot(axis(lane.truth.c1), seg),
                           glm::dot(axis(lane.truth.c2), seg));
    code = encodeDirection(local, params_.alpha);
    const vec3 exact = toVec3(local) * float(1.0 / std::sqrt(len2));
    lane.truth = shader::fibletCompose(lane.truth, shader::fibletLocalTransform(exact, v_, params_.delta));
  }
  w = compose4(w, local4_[code]);
  if (meter_) lane.decoded[lane.first + k] = w.t;
  lane.bytes[lane.base + shader::fibletCodeByte(uint32_t(k))] = uint8_t(code);
  lane.count = k + 1;
  lane.k = k + 1;
  return true;
}

bool FibletEncoder::finishFiblet(Lane& lane) {
  const bool begins = lane.first == 0;
  const bool ends = lane.first + lane.count == lane.n;
  lane.bytes[lane.base + shader::fibletFlagsByte(params_.points_per_fiblet)] =
      uint8_t(shader::fibletFlags(begins, ends, uint32_t(lane.count)));
  ++report_.fiblets;
  ++lane.fiber_fiblets;
  lane.first += lane.count;
  if (ends) return false;
  startFiblet(lane);
  return true;
}

void FibletEncoder::emit(const Lane& lane, size_t offset, uint32_t fiblets, uint32_t points, EncodedFiblets& out) {
  const uint64_t first_fiblet = out.fiblet_base + out.fibletCount();
  if (first_fiblet + fiblets > std::numeric_limits<uint32_t>::max())
    fail("fiblet encoder", "more than 2^32 fiblets in one encoded block");
  out.fiber_first_fiblet.push_back(uint32_t(first_fiblet));
  out.fiber_points.push_back(points);
  const uint8_t* from = lane.bytes.data() + offset;
  out.bytes.insert(out.bytes.end(), from, from + size_t(fiblets) * params_.recordBytes());
}

void FibletEncoder::checkOutput(EncodedFiblets& out) const {
  if (out.record_bytes == 0) out.record_bytes = params_.recordBytes();
  if (out.record_bytes != params_.recordBytes()) fail("fiblet encoder", "output holds records of another size");
}

void FibletEncoder::encodeStreamline(const float* xyz, size_t n, EncodedFiblets& out) {
  checkOutput(out);
  Lane& lane = lanes_[0];
  lane.bytes.clear();
  startFiber(lane, xyz, n);
  if (n > 0) {
    do {
      while (stepFiblet(lane)) {
      }
    } while (finishFiblet(lane));
    if (meter_) measureFiber(lane);
  }
  emit(lane, lane.fiber_offset, lane.fiber_fiblets, uint32_t(n), out);
}

void FibletEncoder::encode(const Tractogram& chunk, EncodedFiblets& out) {
  checkOutput(out);
  // kLanes fibers at a time, a point of each in turn: each point depends on
  // the previous one through the decoded frame (a chain of ~100 cycles of
  // latency), and the lanes' chains overlap in the out-of-order core. Fibers
  // are placed in the lanes' buffers as they finish and copied out in input
  // order, so the output is the same as one fiber after the other.
  const size_t fibers = chunk.streamlineCount();
  placements_.resize(fibers);
  for (Lane& lane : lanes_) lane.bytes.clear();
  size_t next = 0;
  const auto startNext = [&](size_t l) {
    Lane& lane = lanes_[l];
    lane.active = false;
    while (!lane.active && next < fibers) {
      lane.fiber = next;
      startFiber(lane, chunk.point(chunk.offsets[next]), chunk.pointsIn(next));
      if (!lane.active) placements_[next] = {uint8_t(l), lane.fiber_offset, 0};  // empty: no fiblet
      ++next;
    }
  };
  const auto advance = [&](size_t l) {
    Lane& lane = lanes_[l];
    if (stepFiblet(lane) || finishFiblet(lane)) return;
    if (meter_) measureFiber(lane);
    placements_[lane.fiber] = {uint8_t(l), lane.fiber_offset, lane.fiber_fiblets};
    startNext(l);
  };
  for (size_t l = 0; l < kLanes; ++l) startNext(l);
  // While every lane has work, a point of each in turn; then the stragglers.
  bool all_active = true;
  for (const Lane& lane : lanes_) all_active = all_active && lane.active;
  while (all_active) {
    for (size_t l = 0; l < kLanes; ++l) {
      advance(l);
      all_active = all_active && lanes_[l].active;
    }
  }
  for (size_t l = 0; l < kLanes; ++l)
    while (lanes_[l].active) advance(l);
  // Room for the whole chunk first (growing geometrically where encode is
  // called again on the same output): appending record by record grew the
  // bytes by doubling, copying them each time.
  size_t fiblets = 0;
  for (const Placement& p : placements_) fiblets += p.fiblets;
  const auto makeRoom = [](auto& v, size_t more) {
    if (v.capacity() < v.size() + more) v.reserve(std::max(v.size() + more, 2 * v.capacity()));
  };
  makeRoom(out.bytes, fiblets * params_.recordBytes());
  makeRoom(out.fiber_first_fiblet, fibers);
  makeRoom(out.fiber_points, fibers);
  for (size_t s = 0; s < fibers; ++s) {
    const Placement& p = placements_[s];
    emit(lanes_[p.lane], p.offset, p.fiblets, uint32_t(chunk.pointsIn(s)), out);
  }
}

EncodedFiblets encodeTractogram(const Tractogram& tractogram, const CodecParams& params, const EncodeOptions& options,
                                EncodeReport* report) {
  FibletEncoder encoder(params, options);
  EncodedFiblets out;
  out.record_bytes = params.recordBytes();
  out.bytes.reserve(size_t(double(tractogram.pointCount()) / params.points_per_fiblet * 1.05 + 16) *
                    params.recordBytes());
  encoder.encode(tractogram, out);
  if (report) *report = encoder.report();
  return out;
}

namespace {

// Distance from p to the segment [a, b].
double pointSegmentDistance(const float* p, const glm::dvec3& a, const glm::dvec3& b) {
  const glm::dvec3 ab = b - a, ap = glm::dvec3(p[0], p[1], p[2]) - a;
  const double len2 = glm::dot(ab, ab);
  const double u = len2 > 0 ? std::clamp(glm::dot(ab, ap) / len2, 0.0, 1.0) : 0.0;
  return glm::length(ap - u * ab);
}

}  // namespace

void ResampleReport::merge(const ResampleReport& other) {
  const uint64_t measured = measured_points + other.measured_points;
  if (measured > 0)
    mean_deviation_mm =
        (mean_deviation_mm * double(measured_points) + other.mean_deviation_mm * double(other.measured_points)) /
        double(measured);
  measured_points = measured;
  input_points += other.input_points;
  output_points += other.output_points;
  moved_points += other.moved_points;
  max_deviation_mm = std::max(max_deviation_mm, other.max_deviation_mm);
}

// More points than a fiber can have in the fiblet tables (uint32 counts).
constexpr uint64_t kMaxResampledPoints = uint64_t(1) << 31;

Tractogram resampleToStep(const Tractogram& in, double step_mm, ResampleReport* report) {
  if (!(step_mm > 0) || !std::isfinite(step_mm)) fail("resample", "step must be finite and > 0");
  Tractogram out;
  out.per_streamline = in.per_streamline;
  out.per_point.reserve(in.per_point.size());
  for (const DataArray& a : in.per_point) out.per_point.push_back(DataArray{a.name, a.components, a.dtype, {}});
  // The per-point values at the point u of the way from input point i to
  // i + 1 (linear, as the position).
  const auto emitValues = [&](size_t i, double u) {
    for (size_t a = 0; a < in.per_point.size(); ++a) {
      const uint32_t k = in.per_point[a].components;
      const float* v = in.per_point[a].values.data() + i * k;
      for (uint32_t c = 0; c < k; ++c)
        out.per_point[a].values.push_back(u == 0.0 ? v[c] : float((1.0 - u) * double(v[c]) + u * double(v[k + c])));
    }
  };
  ResampleReport counts;
  counts.input_points = in.pointCount();
  double deviation_sum = 0;
  uint64_t deviation_count = 0;
  const double step2 = step_mm * step_mm;
  for (size_t s = 0; s < in.streamlineCount(); ++s) {
    const float* p = in.point(in.offsets[s]);
    const size_t n = in.pointsIn(s);
    // Check before walking: a NaN would never leave the sphere test, and an
    // absurd length would allocate without bound.
    double length = 0;
    for (size_t i = 0; i < 3 * n; ++i)
      if (!std::isfinite(p[i])) fail("resample", "streamline " + std::to_string(s) + " has a non-finite coordinate");
    for (size_t i = 1; i < n; ++i) {
      const float* a = p + 3 * (i - 1);
      length += std::sqrt(std::pow(double(p[3 * i]) - a[0], 2) + std::pow(double(p[3 * i + 1]) - a[1], 2) +
                          std::pow(double(p[3 * i + 2]) - a[2], 2));
    }
    if (length / step_mm > double(kMaxResampledPoints))
      fail("resample", "streamline " + std::to_string(s) + " is " + std::to_string(length) + " mm long, more than " +
                           std::to_string(kMaxResampledPoints) + " steps of " + std::to_string(step_mm) + " mm");
    const size_t first_point = size_t(in.offsets[s]);
    if (n > 0) {
      out.positions.insert(out.positions.end(), p, p + 3);
      emitValues(first_point, 0.0);
    }
    if (n >= 2) {
      glm::dvec3 cur(p[0], p[1], p[2]);
      // Input vertices passed since the last output point: they lie between
      // it and the next one, and are measured against that chord.
      size_t pending_from = 1, pending_to = 1;
      auto measure = [&](const glm::dvec3& from, const glm::dvec3& to) {
        for (size_t i = pending_from; i < pending_to; ++i) {
          const double dev = pointSegmentDistance(p + 3 * i, from, to);
          deviation_sum += dev;
          ++deviation_count;
          counts.max_deviation_mm = std::max(counts.max_deviation_mm, dev);
        }
        pending_from = pending_to;
      };
      size_t seg = 0;  // the position is on segment seg (points seg, seg + 1) at parameter u
      double u = 0;
      while (seg + 1 < n) {
        const float* a = p + 3 * seg;
        const float* b = a + 3;
        const glm::dvec3 bc = glm::dvec3(b[0], b[1], b[2]) - cur;
        if (glm::dot(bc, bc) < step2) {
          ++seg;
          u = 0;
          pending_to = seg + 1 < n ? seg + 1 : seg;  // vertex seg passed (the last one is kept)
          continue;
        }
        // |a + x d - cur| = step has its larger root in [u, 1]: |a + u d -
        // cur| <= step (cur itself or a vertex inside the sphere) and
        // |b - cur| >= step.
        const glm::dvec3 pa(a[0], a[1], a[2]);
        const glm::dvec3 d = glm::dvec3(b[0], b[1], b[2]) - pa;
        const glm::dvec3 e = pa - cur;
        const double qa = glm::dot(d, d);
        const double qb = 2 * glm::dot(d, e);
        const double qc = glm::dot(e, e) - step2;
        const double root = (-qb + std::sqrt(std::max(qb * qb - 4 * qa * qc, 0.0))) / (2 * qa);
        u = std::clamp(root, u, 1.0);
        const glm::dvec3 previous = cur;
        cur = pa + u * d;
        for (int c = 0; c < 3; ++c) out.positions.push_back(float(cur[c]));
        emitValues(first_point + seg, u);
        measure(previous, cur);
        ++counts.moved_points;
      }
      const float* last = p + 3 * (n - 1);
      const glm::dvec3 end(last[0], last[1], last[2]);
      const double gap2 = glm::dot(end - cur, end - cur);
      if (gap2 > 0) {
        out.positions.insert(out.positions.end(), last, last + 3);
        emitValues(first_point + n - 1, 0.0);
      }
      measure(cur, end);
    }
    out.offsets.push_back(out.positions.size() / 3);
  }
  counts.output_points = out.pointCount();
  // Over interior input points only: the first and last are kept exactly.
  counts.mean_deviation_mm = deviation_count ? deviation_sum / double(deviation_count) : 0.0;
  counts.measured_points = deviation_count;
  if (report) *report = counts;
  return out;
}

}  // namespace fibscope
