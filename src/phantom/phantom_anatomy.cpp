// The phantom's anatomy: guide-curve control points of each bundle, in RAS+
// millimetres (x: left to right, y: posterior to anterior, z: inferior to
// superior), inside the 140 x 170 x 120 mm brain ellipsoid.
//
// Positions are drawn from textbook anatomy (MNI-like coordinates scaled to
// the ellipsoid), not from an atlas: the aim is a rendering that reads as a
// tractogram - a corpus callosum fanning to both hemispheres, corticospinal
// tracts fanning from the brainstem to the motor strip, the arcuate's C
// around the Sylvian fissure - with the statistics of tracker output.
#include <algorithm>
#include <array>
#include <cmath>

#include "phantom/phantom_internal.h"

namespace fibscope::phantom_detail {
namespace {

// Depth of cortical endpoints as relative radius: fibers end 1-12% inside
// the surface (roughly the grey/white boundary under a 3 mm cortex).
double corticalDepth(Rng& rng) { return rng.uniform(0.88, 0.99); }

// A point of the unit disk, uniform by area, so fibers fill a bundle's cross
// section evenly.
void diskPoint(Rng& rng, double& u, double& v) {
  const double r = std::sqrt(rng.uniform());
  const double angle = 2.0 * kPi * rng.uniform();
  u = r * std::cos(angle);
  v = r * std::sin(angle);
}

// Moves control point j by radius[j] * (u n_j + v b_j), where (n_j, b_j)
// spans the plane perpendicular to the local direction of the control
// polyline; `reference` must never be parallel to that direction (each
// bundle passes an axis its centreline never runs along). One (u, v) per
// fiber: the fiber keeps its place in the bundle's cross section.
// `scale` multiplies the radii (PhantomOptions::bundle_radius_scale): tracked
// bundles are fat (a tracker's streamlines of one bundle spread over 1-2 cm
// of white matter, not a 5 mm cable), and how thick they are decides how
// much they occlude.
void offsetCrossSection(std::vector<Vec3>& controls, const double* radius, double u, double v, Vec3 reference,
                        double scale) {
  const size_t n = controls.size();
  std::array<Vec3, 16> moved;
  for (size_t j = 0; j < n; ++j) {
    const Vec3 ahead = controls[j + 1 < n ? j + 1 : j], behind = controls[j > 0 ? j - 1 : j];
    const Vec3 t = glm::normalize(ahead - behind);
    const Vec3 nrm = glm::normalize(glm::cross(t, reference));
    const Vec3 bin = glm::cross(t, nrm);
    moved[j] = controls[j] + scale * radius[j] * (u * nrm + v * bin);
    // Fatter bundles can push end controls past the cortex: pulled back to
    // relative radius 0.99 (at scale 1 the phantom stays what it always was).
    if (scale > 1.0 && relativeRadius(moved[j]) > 0.99) moved[j] = atRelativeRadius(moved[j], 0.99);
  }
  for (size_t j = 0; j < n; ++j) controls[j] = moved[j];
}

// Corpus callosum: left-right arcs crossing the midline in a sagittal sheet
// that arches from the genu (y = +34) over the body to the splenium
// (y = -38), then fanning in each hemisphere from lateral to superior
// cortex; genu fibers bend forward (forceps minor), splenium fibers backward
// (forceps major).
void corpusCallosum(Rng& rng, double scale, std::vector<Vec3>& q) {
  const double y0 = rng.uniform(-38.0, 34.0);
  const double arch = (y0 + 2.0) / 36.0;
  const double zc = 10.0 + 12.0 * (1.0 - arch * arch);
  const double thickness = scale * (3.0 + 1.5 * smoothstep(-24.0, -36.0, y0));  // splenium is the thickest part
  const double dz = thickness * rng.uniform(-1.0, 1.0);
  const double forward = 1.2 * smoothstep(16.0, 34.0, y0) - 1.5 * smoothstep(-20.0, -38.0, y0);
  const double elevation = rng.uniform(10.0, 75.0);
  Vec3 side_points[2][3];
  for (int side = 0; side < 2; ++side) {
    const double s = side == 0 ? -1.0 : 1.0;
    const double phi = radians(elevation + rng.uniform(-6.0, 6.0));  // homotopic, not mirror-exact
    const Vec3 over_ventricle = {s * 14.0, y0 + 2.0 * forward, zc + dz + 3.0};
    const Vec3 origin = {s * 16.0, y0 + 5.0 * forward, zc + 0.5 * dz + 4.0};
    const Vec3 direction = glm::normalize(Vec3{s * std::cos(phi), forward, std::sin(phi)});
    const Vec3 end = shellPoint(origin, direction, corticalDepth(rng));
    side_points[side][0] = over_ventricle;
    side_points[side][1] = lerp(origin, end, 0.45);
    side_points[side][2] = end;
  }
  q = {side_points[0][2], side_points[0][1], side_points[0][0], Vec3{0.0, y0, zc + dz},
       side_points[1][0], side_points[1][1], side_points[1][2]};
}

// Corticospinal tract: from the medulla up through the cerebral peduncle and
// the posterior limb of the internal capsule, fanning in the corona radiata
// to the precentral gyrus from the vertex (leg) to the lateral surface
// (face).
void corticospinal(Rng& rng, double s, double scale, std::vector<Vec3>& q) {
  const double fan = rng.uniform();
  const double psi = radians(lerp(82.0, 22.0, fan) + rng.uniform(-4.0, 4.0));
  const Vec3 origin = {s * (12.0 + 10.0 * fan), -18.0, 24.0};
  const Vec3 end = shellPoint(origin, glm::normalize(Vec3{s * std::cos(psi), -0.15, std::sin(psi)}), corticalDepth(rng));
  q = {Vec3{s * 7.0, -24.0, -53.0}, Vec3{s * 11.0, -20.0, -32.0}, Vec3{s * 20.0, -14.0, -6.0},
       Vec3{s * 21.0, -15.0, 8.0}, Vec3{s * (17.0 + 15.0 * fan), -16.0, 26.0 - 4.0 * fan}, end};
  static constexpr double kRadius[] = {2.0, 2.5, 3.0, 3.5, 4.0, 3.0};
  double u, v;
  diskPoint(rng, u, v);
  offsetCrossSection(q, kRadius, u, v, {0.0, 1.0, 0.0}, scale);
}

// Arcuate fasciculus: the C around the Sylvian fissure, from the inferior
// frontal and precentral cortex back through the parietal white matter,
// down around the fissure's posterior end into the temporal lobe; both ends
// fan over a few centimetres of cortex.
void arcuate(Rng& rng, double s, double scale, std::vector<Vec3>& q) {
  const double frontal = rng.uniform(), temporal = rng.uniform();
  const Vec3 front_origin = {s * 34.0, 10.0 + 14.0 * frontal, 16.0 + 8.0 * (frontal - 0.5)};
  const Vec3 front_end = shellPoint(front_origin, glm::normalize(Vec3{s * 1.0, 0.35 + 0.3 * frontal, 0.05}), corticalDepth(rng));
  const Vec3 temporal_origin = {s * 44.0, -14.0 + 14.0 * temporal, -16.0};
  const Vec3 temporal_end = shellPoint(temporal_origin, glm::normalize(Vec3{s * 1.0, 0.25, -0.35}), corticalDepth(rng));
  q = {front_end,
       Vec3{s * 36.0, 2.0 + 6.0 * frontal, 24.0},
       Vec3{s * 37.0, -20.0, 27.0},
       Vec3{s * 40.0, -40.0, 16.0},
       Vec3{s * 44.0, -36.0, -4.0},
       Vec3{s * 47.0, -20.0 + 8.0 * temporal, -14.0},
       temporal_end};
  static constexpr double kRadius[] = {3.0, 3.5, 3.5, 3.5, 3.5, 3.5, 3.0};
  double u, v;
  diskPoint(rng, u, v);
  offsetCrossSection(q, kRadius, u, v, {1.0, 0.0, 0.0}, scale);
}

// Cingulum: above the corpus callosum from the subgenual cortex, around the
// genu, along the body, around the splenium and down into the
// parahippocampal gyrus.
void cingulum(Rng& rng, double s, std::vector<Vec3>& q) {
  q = {Vec3{s * 6.0, 26.0, -8.0},  Vec3{s * 7.0, 38.0, 8.0},   Vec3{s * 8.0, 26.0, 31.0},
       Vec3{s * 8.0, -4.0, 37.0},  Vec3{s * 8.0, -32.0, 32.0}, Vec3{s * 10.0, -48.0, 14.0},
       Vec3{s * 16.0, -45.0, -5.0}, Vec3{s * 22.0, -30.0, -15.0}, Vec3{s * 25.0, -14.0, -20.0}};
  static constexpr double kRadius[] = {2.0, 2.5, 2.5, 2.5, 2.5, 2.5, 2.5, 2.5, 2.0};
  double u, v;
  diskPoint(rng, u, v);
  offsetCrossSection(q, kRadius, u, v, {1.0, 0.0, 0.0}, 1.0);
}

// Inferior fronto-occipital fasciculus: occipital pole, along the lateral
// ventricle's wall, through the temporal stem and extreme capsule, into the
// inferior and orbital frontal cortex.
void ifof(Rng& rng, double s, double scale, std::vector<Vec3>& q) {
  const double occipital = rng.uniform(), frontal = rng.uniform();
  const Vec3 back = shellPoint({s * 26.0, -58.0, 4.0 + 12.0 * (occipital - 0.5)}, glm::normalize(Vec3{s * 0.25, -1.0, 0.05}),
                               corticalDepth(rng));
  const Vec3 front = shellPoint({s * 24.0, 34.0, 2.0 + 14.0 * (frontal - 0.5)},
                                glm::normalize(Vec3{s * (0.15 + 0.3 * frontal), 1.0, 0.1}), corticalDepth(rng));
  q = {back, Vec3{s * 30.0, -48.0, 2.0}, Vec3{s * 34.0, -24.0, -4.0}, Vec3{s * 31.0, -2.0, -8.0},
       Vec3{s * 27.0, 18.0, -2.0}, front};
  static constexpr double kRadius[] = {3.0, 3.5, 3.0, 2.5, 3.0, 3.5};
  double u, v;
  diskPoint(rng, u, v);
  offsetCrossSection(q, kRadius, u, v, {0.0, 0.0, 1.0}, scale);
}

// Inferior longitudinal fasciculus: occipital cortex to the anterior
// temporal lobe, below and lateral to the IFOF.
void ilf(Rng& rng, double s, double scale, std::vector<Vec3>& q) {
  const double occipital = rng.uniform();
  const Vec3 back = shellPoint({s * 32.0, -56.0, -2.0 + 10.0 * (occipital - 0.5)},
                               glm::normalize(Vec3{s * 0.35, -1.0, -0.1}), corticalDepth(rng));
  const Vec3 front = shellPoint({s * 38.0, 10.0, -27.0}, glm::normalize(Vec3{s * 0.2, 1.0, -0.25}), corticalDepth(rng));
  q = {back, Vec3{s * 38.0, -44.0, -6.0}, Vec3{s * 42.0, -22.0, -16.0}, Vec3{s * 40.0, -2.0, -25.0}, front};
  static constexpr double kRadius[] = {3.5, 3.5, 3.0, 3.0, 3.0};
  double u, v;
  diskPoint(rng, u, v);
  offsetCrossSection(q, kRadius, u, v, {0.0, 0.0, 1.0}, scale);
}

// U-fibers: short arcs connecting neighbouring gyri, 1-2 mm under the
// cortex at their ends and 7-10 mm deep at their bottom. Each fiber belongs
// to one of the fixed sites and keeps a lateral offset within it, so they
// render as many small bundles rather than as noise.
void uFiber(Rng& rng, std::vector<Vec3>& q) {
  const auto& sites = uFiberSites();
  const UFiberSite& site = sites[size_t(rng.next() % sites.size())];
  const Vec3 across = glm::cross(site.centre, site.tangent);
  const double half_span = 0.5 * site.span_mm * rng.uniform(0.85, 1.15);
  const double offset = rng.uniform(-3.0, 3.0);
  const double bottom = rng.uniform(0.84, 0.88), top = rng.uniform(0.95, 0.98);
  const Vec3 surface_centre = atRelativeRadius(site.centre, 1.0);
  static constexpr double kAlong[] = {-1.0, -0.6, 0.0, 0.6, 1.0};
  q.clear();
  for (double a : kAlong) {
    const Vec3 towards = surface_centre + (a * half_span) * site.tangent + offset * across;
    q.push_back(atRelativeRadius(towards, bottom + (top - bottom) * a * a));
  }
}

// White matter at large: besides the named bundles, whole-brain tracking
// fills the white matter with fibers in every region, crossing each other,
// a few per cubic millimetre (MRtrix3 iFOD1 seeded in a brain mask: most
// 1 mm voxels of the brain hold 1-4 fibers of a 20 k tractogram, where the
// named bundles alone pack the same fibers into a fifth of the volume at
// several times the density, and so occlude far more). Three families of
// fibers seeded uniformly in the deep white matter follow smooth fields of
// the three kinds of white-matter fibers, the same fields
// scripts/make_tckgen_250mb.sh gives tckgen to track (so the phantom and a
// real tracker's output of the same field can be compared):
//   commissural: circles around an anterior-posterior axis 40 mm below the
//     centre: left-right across the midline, arching down at the sides;
//   association: circles around a left-right axis 60 mm below the centre:
//     front to back, arching down at both ends;
//   projection: rays from a point 100 mm below the centre: brainstem to the
//     cortex, fanning.
// A seed is kept with the family's weight at its place (the tckgen field's
// lobe amplitudes), so commissural fibers are densest near the midline's
// plane y = 0, association fibers laterally, projection fibers in two
// lateral columns.
enum class WhiteMatterFamily { Commissural, Association, Projection };

double familyWeight(WhiteMatterFamily family, Vec3 p) {
  switch (family) {
    case WhiteMatterFamily::Commissural: return std::exp(-(p.y / 55.0) * (p.y / 55.0));
    case WhiteMatterFamily::Association: return std::clamp(std::abs(p.x) / 40.0, 0.35, 1.0);
    case WhiteMatterFamily::Projection: {
      const double d = (std::abs(p.x) - 25.0) / 15.0;
      return 0.3 + 0.7 * std::exp(-d * d);
    }
  }
  return 1.0;
}

// The family's curve through `seed` at parameter t (t = 0 at the seed; arc
// length in mm).
struct FamilyCurve {
  WhiteMatterFamily family;
  Vec3 centre{}, seed{};
  double radius = 0, angle = 0;  // circles: radius (mm) and angle of the seed
  Vec3 direction{};              // rays: unit direction

  Vec3 at(double t) const {
    if (family == WhiteMatterFamily::Projection) return seed + t * direction;
    const double a = angle + t / radius;
    if (family == WhiteMatterFamily::Commissural)
      return centre + radius * Vec3{std::sin(a), 0.0, std::cos(a)};
    return centre + radius * Vec3{0.0, std::sin(a), std::cos(a)};
  }
};

constexpr double kWhiteMatterSeedDepth = 0.85;  // seeds within 85 % of the radius: deep white matter
constexpr double kWhiteMatterMinRadiusMm = 20.0;  // smaller circles would loop inside the brain

FamilyCurve familyCurve(WhiteMatterFamily family, Vec3 seed) {
  FamilyCurve c{family};
  c.seed = seed;
  switch (family) {
    case WhiteMatterFamily::Commissural:
      c.centre = {0.0, seed.y, -40.0};
      c.radius = std::hypot(seed.x - c.centre.x, seed.z - c.centre.z);
      c.angle = std::atan2(seed.x - c.centre.x, seed.z - c.centre.z);
      break;
    case WhiteMatterFamily::Association:
      c.centre = {seed.x, 0.0, -60.0};
      c.radius = std::hypot(seed.y - c.centre.y, seed.z - c.centre.z);
      c.angle = std::atan2(seed.y - c.centre.y, seed.z - c.centre.z);
      break;
    case WhiteMatterFamily::Projection:
      c.direction = glm::normalize(seed - Vec3{0.0, -10.0, -100.0});
      break;
  }
  return c;
}

void whiteMatter(Rng& rng, WhiteMatterFamily family, std::vector<Vec3>& q) {
  // Rejection sampling of the seed: uniform in the deep white matter, kept
  // with the family's weight (>= 0.3 everywhere, so a few draws suffice).
  Vec3 seed{0.0, 0.0, 20.0};
  for (int draw = 0; draw < 256; ++draw) {
    const Vec3 p = {rng.uniform(-1.0, 1.0) * kPhantomSemiAxesMm[0], rng.uniform(-1.0, 1.0) * kPhantomSemiAxesMm[1],
                    rng.uniform(-1.0, 1.0) * kPhantomSemiAxesMm[2]};
    if (relativeRadius(p) > kWhiteMatterSeedDepth) continue;
    if (family != WhiteMatterFamily::Projection && familyCurve(family, p).radius < kWhiteMatterMinRadiusMm) continue;
    if (rng.uniform() >= familyWeight(family, p)) continue;
    seed = p;
    break;
  }
  const FamilyCurve curve = familyCurve(family, seed);
  // Walk both ways from the seed until the cortex (each end at its own
  // cortical depth), at most half a circle each way.
  constexpr double kStepMm = 2.0;
  constexpr int kControlEvery = 5;  // a control point every 10 mm
  const double max_t = family == WhiteMatterFamily::Projection ? 400.0 : 0.5 * kPi * curve.radius;
  double end_t[2] = {0.0, 0.0};
  for (int side = 0; side < 2; ++side) {
    const double depth = corticalDepth(rng), sign = side == 0 ? -1.0 : 1.0;
    double t = 0.0;
    while (t + kStepMm <= max_t && relativeRadius(curve.at(sign * (t + kStepMm))) <= depth) t += kStepMm;
    end_t[side] = sign * t;
  }
  q.clear();
  const int steps = int(std::lround((end_t[1] - end_t[0]) / kStepMm));
  for (int k = 0; k <= steps; ++k)
    if (k % kControlEvery == 0 || k == steps) q.push_back(curve.at(end_t[0] + kStepMm * k));
  if (q.size() < 2) q = {seed, curve.at(1.0)};  // a seed at the cortex: a stub the caller redraws
}

}  // namespace

const std::vector<UFiberSite>& uFiberSites() {
  // A Fibonacci lattice on the sphere (even coverage), without the inferior
  // cap where the brainstem and cerebellum are; tangents and spans from a
  // fixed random stream.
  static const std::vector<UFiberSite> sites = [] {
    constexpr int kLattice = 220;
    const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
    Rng rng(0x75666962657273ull);  // fixed: the anatomy does not depend on the seed
    std::vector<UFiberSite> out;
    for (int i = 0; i < kLattice; ++i) {
      const double z = 1.0 - 2.0 * (i + 0.5) / kLattice;
      const double r = std::sqrt(1.0 - z * z);
      const Vec3 centre = {r * std::cos(golden_angle * i), r * std::sin(golden_angle * i), z};
      const double tangent_angle = 2.0 * kPi * rng.uniform();
      const double span = rng.uniform(16.0, 28.0);
      if (z < -0.4) continue;
      const Vec3 e1 = glm::normalize(glm::cross(centre, std::abs(centre.z) < 0.9 ? Vec3{0, 0, 1} : Vec3{1, 0, 0}));
      const Vec3 e2 = glm::cross(centre, e1);
      out.push_back({centre, std::cos(tangent_angle) * e1 + std::sin(tangent_angle) * e2, span});
    }
    return out;
  }();
  return sites;
}

void fiberControls(PhantomBundle bundle, Rng& rng, double scale, std::vector<Vec3>& controls) {
  switch (bundle) {
    case PhantomBundle::CorpusCallosum: return corpusCallosum(rng, scale, controls);
    case PhantomBundle::CstLeft: return corticospinal(rng, -1.0, scale, controls);
    case PhantomBundle::CstRight: return corticospinal(rng, 1.0, scale, controls);
    case PhantomBundle::ArcuateLeft: return arcuate(rng, -1.0, scale, controls);
    case PhantomBundle::ArcuateRight: return arcuate(rng, 1.0, scale, controls);
    case PhantomBundle::CingulumLeft: return cingulum(rng, -1.0, controls);
    case PhantomBundle::CingulumRight: return cingulum(rng, 1.0, controls);
    case PhantomBundle::IfofLeft: return ifof(rng, -1.0, scale, controls);
    case PhantomBundle::IfofRight: return ifof(rng, 1.0, scale, controls);
    case PhantomBundle::IlfLeft: return ilf(rng, -1.0, scale, controls);
    case PhantomBundle::IlfRight: return ilf(rng, 1.0, scale, controls);
    case PhantomBundle::UFibers: return uFiber(rng, controls);
    case PhantomBundle::WhiteMatterCommissural: return whiteMatter(rng, WhiteMatterFamily::Commissural, controls);
    case PhantomBundle::WhiteMatterAssociation: return whiteMatter(rng, WhiteMatterFamily::Association, controls);
    case PhantomBundle::WhiteMatterProjection: return whiteMatter(rng, WhiteMatterFamily::Projection, controls);
  }
}

double fullSpanProbability(PhantomBundle bundle) {
  switch (bundle) {
    case PhantomBundle::UFibers: return 1.0;  // already short; cut further they would fall under min length
    case PhantomBundle::CingulumLeft:
    case PhantomBundle::CingulumRight: return 0.3;  // long and thin: most streamlines cover part of it
    case PhantomBundle::WhiteMatterCommissural:
    case PhantomBundle::WhiteMatterAssociation:
    case PhantomBundle::WhiteMatterProjection: return 1.0;
    default: return 0.5;
  }
}

}  // namespace fibscope::phantom_detail
