// Internals of the phantom generator shared by its translation units: a small
// double vector, the per-streamline random stream, the guide curve a fiber
// follows and the tracker that walks along it.
//
// Nothing here is public API; include phantom.h instead.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "phantom/phantom.h"

namespace fibscope::phantom_detail {

inline constexpr double kPi = 3.14159265358979323846;
inline double radians(double degrees) { return degrees * (kPi / 180.0); }

// glm's arithmetic is the phantom's: its dot, cross, length and normalize
// evaluate in the order the phantom's own functions did, so the phantom
// stays bit for bit what it was (its determinism tests pin it).
using Vec3 = glm::dvec3;
// a + t (b - a), not glm::mix (a (1 - t) + b t rounds differently).
inline Vec3 lerp(Vec3 a, Vec3 b, double t) { return a + t * (b - a); }
inline double lerp(double a, double b, double t) { return a + t * (b - a); }
inline double smoothstep(double edge0, double edge1, double x) {
  double t = (x - edge0) / (edge1 - edge0);
  t = t < 0 ? 0 : (t > 1 ? 1 : t);
  return t * t * (3 - 2 * t);
}

// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix
// whose outputs pass BigCrush for consecutive inputs. Used both to derive a
// streamline's key from (seed, index, attempt) and as that streamline's
// sequential stream, which makes streamline i a pure function of
// (options, seed, i): no state is shared between streamlines or threads.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

__extension__ using Uint128 = unsigned __int128;

// The sequential stream of one streamline: wyrand (Wang Yi's 64-bit
// generator: a Weyl sequence folded through one 64x64->128-bit multiply),
// which passes BigCrush and PractRand and costs a handful of instructions,
// against the tracker's three normals per step. Its 64-bit state is the
// streamline's key, so a stream depends on (seed, index, attempt) only.
class Rng {
 public:
  explicit Rng(uint64_t key) : state_(key) {}
  uint64_t next() {
    state_ += 0xa0761d6478bd642full;
    const Uint128 m = Uint128(state_) * Uint128(state_ ^ 0xe7037ed1a0b428dbull);
    return uint64_t(m >> 64) ^ uint64_t(m);
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Two approximately standard normals from one draw, each the Irwin-Hall
  // sum of four 8-bit uniforms, centred and scaled to unit variance, summed
  // in SIMD-within-a-register lanes. The support is bounded
  // (|g| <= 3.45), which keeps the tracker's jitter free of wild outliers,
  // and it costs a few integer operations instead of Box-Muller's log,
  // sqrt and trigonometry; the 1/148 sigma granularity is far below
  // anything visible in a fiber.
  void normal2(double& a, double& b) {
    const uint64_t r = next();
    const uint64_t pairs = (r & 0x00ff00ff00ff00ffull) + ((r >> 8) & 0x00ff00ff00ff00ffull);
    const uint64_t quads = (pairs & 0x0000ffff0000ffffull) + ((pairs >> 16) & 0x0000ffff0000ffffull);
    // mean 4 * 255 / 2, variance 4 * (256^2 - 1) / 12
    constexpr double kMean = 510.0, kInverseSigma = 1.0 / 147.80054127;
    a = (double(quads & 0xffffffffu) - kMean) * kInverseSigma;
    b = (double(quads >> 32) - kMean) * kInverseSigma;
  }

 private:
  uint64_t state_;
};

// Key of the random stream of streamline `index`, retry `attempt`.
inline uint64_t streamlineKey(uint64_t seed, uint64_t index, uint32_t attempt) {
  uint64_t k = mix64(seed + 0x5851f42d4c957f2dull);
  k = mix64(k ^ (index + 0x9e3779b97f4a7c15ull));
  return mix64(k ^ (uint64_t(attempt) * 0xd1b54a32d192ed03ull + 0x2545f4914f6cdd1dull));
}

// float(value), as an opaque value the optimiser cannot see through.
// GCC 12.2 at -O2 and above (its SLP vectoriser) turns double(float(x))
// back into x when x, y of a point are rounded together, so a walk that
// goes on from its stored float points would silently go on from the
// unrounded doubles and every segment would carry two roundings instead of
// one (found by Phantom.everySegmentHasTheStepLength; clang 14 is correct).
// An empty asm that claims to modify the float hides its origin.
inline float opaqueFloat(double value) {
  float f = float(value);
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
  asm("" : "+x"(f));
#elif defined(__GNUC__) && defined(__aarch64__)
  asm("" : "+w"(f));
#elif defined(__GNUC__)
  asm("" : "+m"(f));
#endif
  return f;
}

// The ellipsoid of the phantom: (x/a)^2 + (y/b)^2 + (z/c)^2 <= 1, with
// multiplications only: the tracker evaluates it at every step, and
// divisions would compete for the divider with the step's normalisation.
inline constexpr double kInverseSquaredAxes[3] = {1.0 / (kPhantomSemiAxesMm[0] * kPhantomSemiAxesMm[0]),
                                                  1.0 / (kPhantomSemiAxesMm[1] * kPhantomSemiAxesMm[1]),
                                                  1.0 / (kPhantomSemiAxesMm[2] * kPhantomSemiAxesMm[2])};
inline double ellipsoidMeasure(double x, double y, double z) {
  return x * x * kInverseSquaredAxes[0] + y * y * kInverseSquaredAxes[1] + z * z * kInverseSquaredAxes[2];
}
// Relative radius: 1 on the surface, 0.9 at 90% of the way from the centre.
inline double relativeRadius(Vec3 p) { return std::sqrt(ellipsoidMeasure(p.x, p.y, p.z)); }
// `p` moved along the ray from the centre to relative radius `rho`.
inline Vec3 atRelativeRadius(Vec3 p, double rho) { return (rho / relativeRadius(p)) * p; }
// Where the ray origin + t * direction (t > 0) reaches relative radius `rho`,
// for an origin inside that shell.
Vec3 shellPoint(Vec3 origin, Vec3 direction, double rho);

// A polyline sampled from a fiber's smooth guide curve, with each segment's
// unit tangent and the arc length at its start and end.
struct Guide {
  std::vector<Vec3> points;
  std::vector<Vec3> tangents;  // tangents[i] = unit (points[i+1] - points[i])
  std::vector<double> arc;     // arc[i] = arc length at points[i]; arc.size() == points.size()
  // ends[i] = arc[i + 1], except the last, which is +infinity: walks along
  // the guide stop on the last segment without a bounds check.
  std::vector<double> ends;
  double length() const { return arc.empty() ? 0.0 : arc.back(); }
};

// Samples the centripetal Catmull-Rom spline through `controls` (at least
// two points, consecutive points distinct) every `spacing` mm or less into
// `guide`. The centripetal parameterisation (alpha = 1/2) never forms cusps
// or self-intersections within a span, so unevenly spaced anatomical control
// points still give a smooth curve.
void buildGuide(const std::vector<Vec3>& controls, double spacing, Guide& guide);

// Constants of the tracker, derived once from the options.
struct TrackerParameters {
  double step = 0.1;          // mm, every segment has exactly this length
  double lookahead = 4.0;     // mm, pure-pursuit distance along the guide
  double steer = 0.1;         // fraction of the way turned towards the target per step
  double jitter_sigma = 0.0;  // radians, per-axis direction noise per step
  double cos_max_turn = 1.0;  // cos and sin of the largest turn the tracker takes
  double sin_max_turn = 0.0;
};

// Tracks from arc length `start_arc` of `guide` (which must have at least
// one segment) for at most `steps` steps, appending the points (x, y, z
// floats) to `xyz`. Every step is exactly params.step long measured between
// the stored float points (to float precision), turns by at most the
// parameters' maximum turn, and the walk stops before the first point that
// would leave the phantom's ellipsoid.
// Returns the number of points appended: 0 when the start is outside.
size_t trackAlongGuide(const Guide& guide, double start_arc, size_t steps, const TrackerParameters& params, Rng& rng,
                       std::vector<float>& xyz);

// Anatomy: the brain-like bundles and the U-fiber sites under the cortex.
struct UFiberSite {
  Vec3 centre;   // unit direction from the origin to the site
  Vec3 tangent;  // unit, perpendicular to centre: the direction the U spans
  double span_mm = 20;
};
// The fixed table of U-fiber sites (same for every seed: anatomy does not
// change with the tracking seed).
const std::vector<UFiberSite>& uFiberSites();

// Draws the shape of one fiber of bundle `bundle` from `rng` and writes the
// control points of its guide curve (cortex to cortex, or brainstem to
// cortex), in a canonical order (the caller may reverse it). Every control
// point lies inside the ellipsoid, at relative radius 0.99 or less.
// `radius_scale` multiplies the bundles' cross-section radii.
void fiberControls(PhantomBundle bundle, Rng& rng, double radius_scale, std::vector<Vec3>& controls);

// Probability that a fiber of `bundle` covers its whole guide rather than a
// random part of it (tracking stops early in real data: low FOD amplitude,
// crossing regions, seeds in the middle of a bundle).
double fullSpanProbability(PhantomBundle bundle);

}  // namespace fibscope::phantom_detail
