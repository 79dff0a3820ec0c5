// The phantom's tracker: a guide curve through anatomical control points and
// a constant-step walk along it with probabilistic-tracker-like jitter.
#include <algorithm>
#include <cmath>
#include <limits>

#include "phantom/phantom_internal.h"

namespace fibscope::phantom_detail {

Vec3 shellPoint(Vec3 origin, Vec3 direction, double rho) {
  // |D (o + t d)|^2 = rho^2 with D = diag(1/a, 1/b, 1/c): a quadratic in t
  // whose positive root exists because the origin is inside the shell.
  const Vec3 inv = {1.0 / kPhantomSemiAxesMm[0], 1.0 / kPhantomSemiAxesMm[1], 1.0 / kPhantomSemiAxesMm[2]};
  const Vec3 o = {origin.x * inv.x, origin.y * inv.y, origin.z * inv.z};
  const Vec3 d = {direction.x * inv.x, direction.y * inv.y, direction.z * inv.z};
  const double a = glm::dot(d, d), b = glm::dot(o, d), c = glm::dot(o, o) - rho * rho;
  const double t = (-b + std::sqrt(std::max(0.0, b * b - a * c))) / a;
  return origin + t * direction;
}

void buildGuide(const std::vector<Vec3>& controls, double spacing, Guide& guide) {
  guide.points.clear();
  guide.tangents.clear();
  guide.arc.clear();
  guide.ends.clear();
  const size_t n = controls.size();
  auto control = [&](ptrdiff_t i) -> Vec3 {
    // Reflected phantom points beyond both ends make the end spans start and
    // finish along the first and last chords.
    if (i < 0) return 2.0 * controls[0] - controls[1];
    if (size_t(i) >= n) return 2.0 * controls[n - 1] - controls[n - 2];
    return controls[size_t(i)];
  };
  for (size_t span = 0; span + 1 < n; ++span) {
    const Vec3 p0 = control(ptrdiff_t(span) - 1), p1 = control(ptrdiff_t(span)), p2 = control(ptrdiff_t(span) + 1),
               p3 = control(ptrdiff_t(span) + 2);
    // Centripetal knots: t_{i+1} - t_i = |P_{i+1} - P_i|^(1/2).
    const double t0 = 0, t1 = t0 + std::sqrt(std::max(glm::length(p1 - p0), 1e-9)),
                 t2 = t1 + std::sqrt(std::max(glm::length(p2 - p1), 1e-9)), t3 = t2 + std::sqrt(std::max(glm::length(p3 - p2), 1e-9));
    const size_t samples = std::max<size_t>(1, size_t(std::ceil(glm::length(p2 - p1) / spacing)));
    const double r10 = 1.0 / (t1 - t0), r21 = 1.0 / (t2 - t1), r32 = 1.0 / (t3 - t2), r20 = 1.0 / (t2 - t0),
                 r31 = 1.0 / (t3 - t1);
    for (size_t k = 0; k < samples; ++k) {
      // Barry-Goldman pyramid evaluation of the Catmull-Rom span at t.
      const double t = t1 + (t2 - t1) * double(k) / double(samples);
      const Vec3 a1 = ((t1 - t) * r10) * p0 + ((t - t0) * r10) * p1;
      const Vec3 a2 = ((t2 - t) * r21) * p1 + ((t - t1) * r21) * p2;
      const Vec3 a3 = ((t3 - t) * r32) * p2 + ((t - t2) * r32) * p3;
      const Vec3 b1 = ((t2 - t) * r20) * a1 + ((t - t0) * r20) * a2;
      const Vec3 b2 = ((t3 - t) * r31) * a2 + ((t - t1) * r31) * a3;
      guide.points.push_back(((t2 - t) * r21) * b1 + ((t - t1) * r21) * b2);
    }
  }
  guide.points.push_back(controls[n - 1]);

  // Segment tangents and arc lengths; degenerate segments are dropped so that
  // every tangent is a unit vector.
  size_t kept = 1;
  for (size_t i = 1; i < guide.points.size(); ++i)
    if (glm::length(guide.points[i] - guide.points[kept - 1]) > 1e-9) guide.points[kept++] = guide.points[i];
  guide.points.resize(kept);
  guide.arc.push_back(0.0);
  for (size_t i = 0; i + 1 < guide.points.size(); ++i) {
    const Vec3 chord = guide.points[i + 1] - guide.points[i];
    const double length = glm::length(chord);
    guide.tangents.push_back((1.0 / length) * chord);
    guide.arc.push_back(guide.arc.back() + length);
  }
  guide.ends.assign(guide.arc.begin() + 1, guide.arc.end());
  if (!guide.ends.empty()) guide.ends.back() = std::numeric_limits<double>::infinity();
}

size_t trackAlongGuide(const Guide& guide, double start_arc, size_t steps, const TrackerParameters& params, Rng& rng,
                       std::vector<float>& xyz) {
  const Vec3* points = guide.points.data();
  const Vec3* tangents = guide.tangents.data();
  const double* arc = guide.arc.data();
  const double* ends = guide.ends.data();

  // Segment holding the start.
  size_t seg = 0;
  while (start_arc >= ends[seg]) ++seg;
  Vec3 start = points[seg] + (start_arc - arc[seg]) * tangents[seg];
  Vec3 dir = tangents[seg];

  // Every point is stored as float and the walk goes on from the stored
  // value (not from the double it was rounded from): a segment's error is
  // then one rounding of one endpoint, never an accumulated drift.
  const size_t base = xyz.size();
  xyz.resize(base + 3 * (steps + 1));
  float* out = xyz.data() + base;
  out[0] = opaqueFloat(start.x);
  out[1] = opaqueFloat(start.y);
  out[2] = opaqueFloat(start.z);
  if (ellipsoidMeasure(out[0], out[1], out[2]) > 1.0) {
    xyz.resize(base);
    return 0;
  }
  Vec3 pos = {out[0], out[1], out[2]};
  size_t count = 1;

  size_t target_seg = seg;
  const double inv_lookahead = 1.0 / params.lookahead;
  const bool jitter = params.jitter_sigma > 0;
  // Pure pursuit: the fiber steers towards the guide point `lookahead` mm
  // ahead of its projection on the guide (extrapolated along the last
  // tangent past the guide's end), so a fiber that drifts sideways is pulled
  // back within a few millimetres. `want` is that target's direction, scaled
  // by 1 / lookahead: the fiber stays within a fraction of a millimetre of
  // its guide, so |target - pos| is the lookahead to within a few percent,
  // and dividing by the constant instead of the distance only changes the
  // steering strength by as much while saving a square root and a division.
  auto pursue = [&] {
    // Projection on the current guide segment, moving on while the fiber has
    // passed the segment's end.
    double along = arc[seg] + glm::dot(pos - points[seg], tangents[seg]);
    while (along > ends[seg]) {
      ++seg;
      along = arc[seg] + glm::dot(pos - points[seg], tangents[seg]);
    }
    const double target_arc = along + params.lookahead;
    if (target_seg < seg) target_seg = seg;
    while (target_arc >= ends[target_seg]) ++target_seg;
    const Vec3 target = points[target_seg] + (target_arc - arc[target_seg]) * tangents[target_seg];
    return inv_lookahead * (target - pos);
  };

  Vec3 want = pursue();
  for (size_t s = 0; s < steps; ++s) {
    // Relaxation towards the target at rate `steer` per step (with steer =
    // step / (lookahead / 4) the pursuit is critically damped) plus
    // isotropic jitter; the component of the jitter along `dir` only
    // changes the length, which normalising removes, so the turn is the
    // perpendicular part: per-axis sigma.
    //
    // `want` was seen from the previous point: one step of lag, invisible
    // against a millimetre-scale pursuit, that takes the pursuit off the
    // dependency chain position -> direction -> position, so the processor
    // overlaps it with this step's normalisation (about twice as fast).
    Vec3 next = dir + params.steer * (want - dir);
    want = pursue();
    if (jitter) {
      double gx, gy, gz, unused;
      rng.normal2(gx, gy);
      rng.normal2(gz, unused);
      next = next + params.jitter_sigma * Vec3{gx, gy, gz};
    }
    next = (1.0 / glm::length(next)) * next;

    // Bound the turn: rotate `dir` by exactly the maximum angle towards
    // `next` when the turn would exceed it.
    const double cos_turn = glm::dot(dir, next);
    if (cos_turn < params.cos_max_turn) {
      Vec3 side = next - cos_turn * dir;
      double side_length = glm::length(side);
      if (side_length < 1e-12) {  // a full reversal: any perpendicular will do
        side = std::abs(dir.x) < 0.9 ? glm::cross(dir, Vec3{1, 0, 0}) : glm::cross(dir, Vec3{0, 1, 0});
        side_length = glm::length(side);
      }
      next = params.cos_max_turn * dir + (params.sin_max_turn / side_length) * side;
      next = (1.0 / glm::length(next)) * next;
    }

    const Vec3 p = pos + params.step * next;
    const float qx = opaqueFloat(p.x), qy = opaqueFloat(p.y), qz = opaqueFloat(p.z);
    // Fibers end at the brain's surface: the first point that would be
    // outside the ellipsoid is not stored.
    if (ellipsoidMeasure(qx, qy, qz) > 1.0) break;
    float* q = out + 3 * count;
    q[0] = qx;
    q[1] = qy;
    q[2] = qz;
    ++count;
    pos = {qx, qy, qz};
    dir = next;
  }
  xyz.resize(base + 3 * count);
  return count;
}

}  // namespace fibscope::phantom_detail
