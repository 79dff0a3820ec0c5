#include "tubes/tube_intersect.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "shared/render_config.h"

namespace fibscope {
namespace {

constexpr int kBisections = 10;
constexpr int kMinimumSamples = 4;  // pieces of a g >= 0 interval searched for f's minimum

glm::dvec3 xyz(const shader::vec4& v) { return {v.x, v.y, v.z}; }

// Polynomial c[0] + c[1] t + ... + c[N-1] t^(N-1).
template <size_t N>
double evalPoly(const std::array<double, N>& c, double t) {
  double v = c[N - 1];
  for (size_t i = N - 1; i-- > 0;) v = v * t + c[i];
  return v;
}
template <size_t N>
std::array<double, N - 1> derivative(const std::array<double, N>& c) {
  std::array<double, N - 1> d{};
  for (size_t i = 1; i < N; ++i) d[i - 1] = double(i) * c[i];
  return d;
}

// Bisection of a sign change of f on [lo, hi], kBisections halvings; the
// midpoint of the last bracket.
template <typename F>
double bisect(const F& f, double lo, double hi) {
  const bool lo_negative = f(lo) < 0;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    if ((f(mid) < 0) == lo_negative)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

// Sorted breakpoints {0, roots of f in (0, 1) where f is monotone between
// the given breakpoints, 1}.
template <typename F>
std::vector<double> monotoneRoots(const F& f, const std::vector<double>& breaks) {
  std::vector<double> out = {0.0};
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double a = breaks[i], b = breaks[i + 1];
    if ((f(a) < 0) != (f(b) < 0)) out.push_back(bisect(f, a, b));
    if (i + 2 < breaks.size()) out.push_back(b);
  }
  out.push_back(1.0);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace

glm::dvec3 tubeQuadraticCenter(const shader::TubeQuadratic& q, double t) {
  const double a = (1 - t) * (1 - t), b = 2 * t * (1 - t), c = t * t;
  return a * xyz(q.b0) + b * xyz(q.b1) + c * xyz(q.b2);
}

double tubeQuadraticRadius(const shader::TubeQuadratic& q, double t) {
  return (1 - t) * (1 - t) * q.b0.w + 2 * t * (1 - t) * q.b1.w + t * t * q.b2.w;
}

TubeRayHit intersectTubeQuadratic(const shader::TubeQuadratic& q, const glm::dvec3& o, const glm::dvec3& d) {
  // Power basis: c(t) - o = A t^2 + B t + C, r(t) = ra t^2 + rb t + rc.
  const glm::dvec3 b0 = xyz(q.b0), b1 = xyz(q.b1), b2 = xyz(q.b2);
  const glm::dvec3 A = b0 - 2.0 * b1 + b2, B = 2.0 * (b1 - b0), C = b0 - o;
  const double ra = double(q.b0.w) - 2.0 * q.b1.w + q.b2.w, rb = 2.0 * (double(q.b1.w) - q.b0.w), rc = q.b0.w;
  // Along the ray and across it (the offsets from the ray, without the
  // cancellation of |c - o|^2 - ((c - o).d)^2 far from the eye).
  const double za = glm::dot(A, d), zb = glm::dot(B, d), zc = glm::dot(C, d);
  const glm::dvec3 Ap = A - za * d, Bp = B - zb * d, Cp = C - zc * d;
  const std::array<double, 5> g = {
      rc * rc - glm::dot(Cp, Cp),
      2 * rb * rc - 2 * glm::dot(Bp, Cp),
      rb * rb + 2 * ra * rc - glm::dot(Bp, Bp) - 2 * glm::dot(Ap, Cp),
      2 * ra * rb - 2 * glm::dot(Ap, Bp),
      ra * ra - glm::dot(Ap, Ap),
  };
  const std::array<double, 4> g1 = derivative(g);
  const std::array<double, 3> g2 = derivative(g1);
  const auto G = [&](double t) { return evalPoly(g, t); };
  const auto G1 = [&](double t) { return evalPoly(g1, t); };

  // 1. The cascade: g'' in closed form, then g', then g.
  std::vector<double> breaks = {0.0, 1.0};
  if (g2[2] != 0) {
    const double disc = g2[1] * g2[1] - 4 * g2[2] * g2[0];
    if (disc >= 0) {
      const double s = std::sqrt(disc);
      // The stable pair of roots.
      const double k = -0.5 * (g2[1] + (g2[1] >= 0 ? s : -s));
      for (double r : {k / g2[2], k != 0 ? g2[0] / k : -1.0})
        if (r > 0 && r < 1) breaks.push_back(r);
    }
  } else if (g2[1] != 0) {
    const double r = -g2[0] / g2[1];
    if (r > 0 && r < 1) breaks.push_back(r);
  }
  std::sort(breaks.begin(), breaks.end());
  breaks = monotoneRoots(G1, breaks);
  breaks = monotoneRoots(G, breaks);

  // 2. The front of f on each interval where g >= 0.
  const auto Z = [&](double t) { return (za * t + zb) * t + zc; };
  const auto Z1 = [&](double t) { return 2 * za * t + zb; };
  const auto F = [&](double t) { return Z(t) - std::sqrt(std::max(G(t), 0.0)); };
  const auto Phi = [&](double t) { return 2 * Z1(t) * std::sqrt(std::max(G(t), 0.0)) - G1(t); };
  TubeRayHit best;
  double best_s = std::numeric_limits<double>::infinity();
  const auto consider = [&](double t) {
    if (G(t) < 0) return;
    const double s = F(t);
    if (s > 0 && s < best_s) {
      best_s = s;
      best.t = t;
    }
  };
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    const double a = breaks[i], b = breaks[i + 1];
    if (G(0.5 * (a + b)) < 0) continue;
    if (a == 0.0) consider(0.0);
    if (b == 1.0) consider(1.0);
    double prev_t = a, prev_phi = Phi(a);
    for (int k = 1; k <= kMinimumSamples; ++k) {
      const double t = a + (b - a) * k / kMinimumSamples;
      const double phi = Phi(t);
      if (prev_phi < 0 && phi >= 0) consider(bisect(Phi, prev_t, t));
      prev_t = t;
      prev_phi = phi;
    }
  }
  if (!std::isfinite(best_s)) return best;
  best.hit = true;
  best.distance = best_s;
  const glm::dvec3 x = o + best_s * d;
  const glm::dvec3 n = x - tubeQuadraticCenter(q, best.t);
  const double l = glm::length(n);
  best.normal = l > 0 ? n / l : -d;
  return best;
}

TubeRayHit intersectTubeQuadraticBruteForce(const shader::TubeQuadratic& q, const glm::dvec3& o, const glm::dvec3& d,
                                            uint32_t samples) {
  // Front distance of the sphere at t, +inf where the ray misses it.
  const auto front = [&](double t) {
    const glm::dvec3 oc = o - tubeQuadraticCenter(q, t);
    const double r = tubeQuadraticRadius(q, t);
    const double b = glm::dot(oc, d);
    const glm::dvec3 h = oc - b * d;
    const double disc = r * r - glm::dot(h, h);
    if (r <= 0 || disc < 0) return std::numeric_limits<double>::infinity();
    const double s = -b - std::sqrt(disc);
    return s > 0 ? s : std::numeric_limits<double>::infinity();
  };
  double best_t = 0, best_s = std::numeric_limits<double>::infinity();
  for (uint32_t k = 0; k <= samples; ++k) {
    const double t = double(k) / samples, s = front(t);
    if (s < best_s) {
      best_s = s;
      best_t = t;
    }
  }
  TubeRayHit hit;
  if (!std::isfinite(best_s)) return hit;
  // Golden-section search over the neighbouring samples.
  double lo = std::max(0.0, best_t - 1.0 / samples), hi = std::min(1.0, best_t + 1.0 / samples);
  const double phi = 0.5 * (std::sqrt(5.0) - 1);
  for (int i = 0; i < 60; ++i) {
    const double m1 = hi - phi * (hi - lo), m2 = lo + phi * (hi - lo);
    if (front(m1) < front(m2))
      hi = m2;
    else
      lo = m1;
  }
  for (double t : {0.5 * (lo + hi), best_t})
    if (front(t) <= best_s) {
      best_s = front(t);
      best_t = t;
    }
  hit.hit = true;
  hit.distance = best_s;
  hit.t = best_t;
  hit.normal = glm::normalize(o + best_s * d - tubeQuadraticCenter(q, best_t));
  return hit;
}

shader::TubeQuadratic tubeSubSegment(const TubeModel& model, uint32_t index) {
  const shader::TubeSegment& s = model.segments[index / 2];
  return shader::tubeQuadratic(model.nodes[s.node], model.nodes[s.node + 1], s.chord, index % 2);
}

size_t TubeReferenceImage::covered() const {
  return size_t(std::count_if(fiber.begin(), fiber.end(), [](uint32_t f) { return f != shader::kNoFiberId; }));
}

void tubePixelRay(const Camera& camera, uint32_t px, uint32_t py, glm::dvec3& origin, glm::dvec3& direction) {
  const std::array<double, 16> view = viewMatrixD(camera), projection = projectionMatrixD(camera);
  // The view's axes in world space are the rows of its rotation; the eye
  // ray through NDC (x, y) is (x / P00, y / P11, -1) in view space.
  const glm::dvec3 right(view[0], view[4], view[8]), up(view[1], view[5], view[9]), back(view[2], view[6], view[10]);
  const double x_ndc = (px + 0.5) / camera.width * 2 - 1, y_ndc = (py + 0.5) / camera.height * 2 - 1;
  origin = glm::dvec3(camera.eye[0], camera.eye[1], camera.eye[2]);
  direction = glm::normalize(x_ndc / projection[0] * right + y_ndc / projection[5] * up - back);
}

TubeReferenceImage TubeReferenceImage::empty(const Camera& camera) {
  TubeReferenceImage image;
  image.width = camera.width;
  image.height = camera.height;
  const size_t pixels = size_t(camera.width) * camera.height;
  image.depth.assign(pixels, 1.0f);
  image.distance.assign(pixels, 0.0);
  image.fiber.assign(pixels, shader::kNoFiberId);
  image.position.assign(pixels, 0.0f);
  image.normal.assign(pixels, glm::vec3(0.0f));
  return image;
}

TubeReferenceImage renderReferenceTubes(const TubeModel& model, const Camera& camera, TubeReferenceMethod method,
                                        uint32_t brute_force_samples) {
  const std::array<double, 16> vp = viewProjectionD(camera);  // validates the camera
  TubeReferenceImage image = TubeReferenceImage::empty(camera);
  std::vector<shader::TubeQuadratic> subs(model.subSegmentCount());
  // A sphere around each sub-segment: the swept spheres lie in the control
  // points' hull widened by the largest radius control. Rays that miss it
  // skip the sub-segment (the same image, faster).
  std::vector<glm::dvec4> bounds(subs.size());
  for (uint32_t i = 0; i < subs.size(); ++i) {
    const shader::TubeQuadratic& q = subs[i] = tubeSubSegment(model, i);
    const glm::dvec3 c = (xyz(q.b0) + xyz(q.b1) + xyz(q.b2)) / 3.0;
    const double r = std::max({glm::distance(c, xyz(q.b0)), glm::distance(c, xyz(q.b1)), glm::distance(c, xyz(q.b2))}) +
                     std::max({double(q.b0.w), double(q.b1.w), double(q.b2.w)});
    bounds[i] = glm::dvec4(c, r * (1 + 1e-9) + 1e-9);
  }
  const auto clipDepth = [&](const glm::dvec3& p) {
    const double z = vp[2] * p.x + vp[6] * p.y + vp[10] * p.z + vp[14];
    const double w = vp[3] * p.x + vp[7] * p.y + vp[11] * p.z + vp[15];
    return w > 0 ? z / w : -1.0;
  };
  for (uint32_t py = 0; py < camera.height; ++py)
    for (uint32_t px = 0; px < camera.width; ++px) {
      glm::dvec3 o, d;
      tubePixelRay(camera, px, py, o, d);
      const size_t p = size_t(py) * camera.width + px;
      double best = 1.0;
      for (uint32_t i = 0; i < subs.size(); ++i) {
        const glm::dvec3 oc = glm::dvec3(bounds[i]) - o;
        const double along = glm::dot(oc, d);
        if (glm::dot(oc, oc) - along * along > bounds[i].w * bounds[i].w) continue;
        const TubeRayHit h = method == TubeReferenceMethod::Cascade
                                 ? intersectTubeQuadratic(subs[i], o, d)
                                 : intersectTubeQuadraticBruteForce(subs[i], o, d, brute_force_samples);
        if (!h.hit) continue;
        const double depth = clipDepth(o + h.distance * d);
        if (!(depth >= 0 && depth <= 1) || !(depth < best)) continue;
        best = depth;
        const shader::TubeSegment& s = model.segments[i / 2];
        const float p0 = model.nodes[s.node].point, p1 = model.nodes[s.node + 1].point;
        image.depth[p] = float(depth);
        image.distance[p] = h.distance;
        image.fiber[p] = s.fiber;
        image.position[p] = p0 + (p1 - p0) * float(0.5 * ((i % 2) + h.t));
        image.normal[p] = glm::vec3(h.normal);
      }
    }
  return image;
}

}  // namespace fibscope
