// The tessellated spline tubes (tube_tess_stage.h: tube_tess.vert / .tesc /
// .tese / .frag) against the CPU reference of the ray-cast tubes
// (src/tubes/tube_intersect.h, the seed's sphere-swept model) on the same
// tube model: coverage and fiber ids agree, silhouettes within a pixel,
// depths within the tessellation's own error (derived below from the
// geometry: faceting, ring spacing, the model difference); rings do not
// twist on sharp turns and a helix; supersampled coverage (tube_msaa)
// matches too; the tube's colour along it as the
// compute ray caster's; back-patch and frustum culling change
// no texel; a one-point tube is a
// sphere; an empty model draws nothing (tubes and lines occluding each
// other: gpu_tube_raycast_test.cpp, for every method). Validation layers on; frames
// <= 128 x 96. FIBSCOPE_TUBE_TESS_PNG=DIR writes the images' normals as
// PNGs to DIR for a look.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "core/error.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "io/png_writer.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/gbuffer.h"
#include "tube_test_scenes.h"
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/gpu/tube_tess_stage.h"
#include "tubes/tube_intersect.h"

namespace fibscope {
namespace {

class GpuTubeTess : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (!context().enabledFeatures().tessellationShader || !context().info().queue_has_graphics)
      GTEST_SKIP() << "the device has no tessellation shaders or no graphics queue";
  }
  // The surface target of one frame of `model` (setup and the tessellation
  // stage only).
  std::vector<shader::SurfaceTexel> draw(const TubeModel& model, const Camera& camera, TubeTessOptions options = {},
                                         FrameStats* stats = nullptr, RenderSettings settings = {}) {
    GpuTubes tubes = uploadTubes(context(), model);
    std::vector<shader::SurfaceTexel> surface;
    try {
      FrameRenderer renderer(context(), camera.width, camera.height,
                             {makeSetupStage, tubeTessellationStage(&tubes, options)});
      const FrameStats frame = renderer.render(camera, settings, GpuScene());
      if (stats) *stats = frame;
      surface = downloadSurface(context(), renderer.targets());
    } catch (...) {
      destroyTubes(context(), tubes);
      throw;
    }
    destroyTubes(context(), tubes);
    return surface;
  }
};

void maybeWritePng(const std::string& name, const std::vector<shader::SurfaceTexel>& s, const Camera& camera) {
  const char* dir = std::getenv("FIBSCOPE_TUBE_TESS_PNG");
  if (!dir) return;
  std::vector<uint8_t> rgba;
  for (const shader::SurfaceTexel& t : s) {
    const std::array<float, 3> n = test::unpackTangent(t.normal);
    const bool hit = t.depth < 1.0f;
    for (int k = 0; k < 3; ++k) rgba.push_back(hit ? uint8_t(std::lround(127.5f + 127.5f * n[k])) : 0);
    rgba.push_back(255);
  }
  std::string file = name;
  for (char& c : file)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  writePngRgba(std::string(dir) + "/" + file + ".png", camera.width, camera.height, rgba);
}

// How far the tessellated surface may lie from the reference's along a
// surface normal (mm), and its position along the fiber (points), from the
// model's geometry:
//  - faceting: a triangle of the mesh (no refinement) lies within
//    r (1 - cos(rho)) of the surface, rho its circumradius in radians on
//    the surface, at most half the diagonal of its quad: alpha = 2 pi /
//    vertices around, beta = the larger of a ring spacing (ds / r) and a
//    cap's latitude step (pi / 2 over ceil(vertices / 2), tube_tess.tesc);
//  - ring spacing: the chord between rings, ds = chord / rings, lies
//    ds_outer^2 / (8 (rho + r)) inside the outer side of a bend of centre
//    radius rho (ds_outer = ds (rho + r) / rho), rho from the nodes'
//    turning per mm;
//  - the models: the reference sweeps spheres along two quadratics per
//    Hermite segment (centre and radius quadratic in their own parameter
//    t), the tessellation puts circles normal to the Hermite curve (centre
//    and radius Hermite in u): the largest distance of a Hermite point to
//    the nearest quadratic point plus the radii's difference there
//    (sampled), with the difference of the two parameters there (the
//    position along the fiber is interpolated in each), and the
//    sphere-swept radius r / sqrt(1 - r'^2) against r;
//  - position along the fiber, besides the parameters' difference: the
//    sphere-swept surface touches its sphere r r' along the tube from the
//    sphere's centre (where the reference takes the position), and the
//    tessellation interpolates u linearly over triangles whose rings are
//    1 / rings of a segment apart: half that spacing, stretched by
//    (1 + r / rho) on the outer side of a bend.
struct Tolerance {
  double surface_mm = 0, position_points = 0;
  double mm_per_point = 1e30;  // the shortest chord per point along a fiber
};

Tolerance tessellationTolerance(const TubeModel& model, int rings, int vertices) {
  double facet = 0, along = 0, curve = 0, swept = 0, mm_per_point = 1e30;
  double param = 0, contact = 0, spacing = 0;
  for (const shader::TubeSegment& s : model.segments) {
    const shader::TubeNode &a = model.nodes[s.node], &b = model.nodes[s.node + 1];
    const double r = std::max(a.position_radius.w, b.position_radius.w);
    const double alpha = 2.0 * std::numbers::pi / vertices;
    const double beta = std::max(0.5 * std::numbers::pi / std::ceil(vertices / 2.0), s.chord / rings / r);
    facet = std::max(facet, r * (1.0 - std::cos(0.5 * std::sqrt(alpha * alpha + beta * beta))));
    if (s.chord > 0 && b.point > a.point) mm_per_point = std::min(mm_per_point, double(s.chord) / (b.point - a.point));
    const glm::vec3 ta(a.tangent_dradius.x, a.tangent_dradius.y, a.tangent_dradius.z);
    const glm::vec3 tb(b.tangent_dradius.x, b.tangent_dradius.y, b.tangent_dradius.z);
    if (s.chord > 0) {
      const double turn = std::acos(std::clamp(double(glm::dot(ta, tb)), -1.0, 1.0));
      const double rho = turn > 1e-6 ? s.chord / turn : 1e30;
      const double ds = s.chord / rings * (rho + r) / rho;
      along = std::max(along, ds * ds / (8.0 * (rho + r)));
      const uint32_t index = uint32_t(&s - model.segments.data());
      for (int k = 0; k <= 64; ++k) {
        const float u = float(k) / 64.0f;
        const glm::dvec3 h(tubeSegmentPoint(model, s, u));
        // The Hermite radius at u, as glsl/tube_tess.glsl's.
        const double u2 = double(u) * u, u3 = u2 * u;
        const double radius = (2 * u3 - 3 * u2 + 1) * a.position_radius.w +
                              (u3 - 2 * u2 + u) * s.chord * a.tangent_dradius.w +
                              (-2 * u3 + 3 * u2) * b.position_radius.w + (u3 - u2) * s.chord * b.tangent_dradius.w;
        double best = 1e30, best_u = 0;
        for (uint32_t half = 0; half < 2; ++half) {
          const shader::TubeQuadratic q = tubeSubSegment(model, 2 * index + half);
          for (int j = 0; j <= 256; ++j) {
            const double t = j / 256.0;
            const double e =
                glm::distance(h, tubeQuadraticCenter(q, t)) + std::fabs(radius - tubeQuadraticRadius(q, t));
            if (e < best) {
              best = e;
              best_u = 0.5 * (half + t);
            }
          }
        }
        curve = std::max(curve, best);
        param = std::max(param, std::fabs(best_u - u) * std::fabs(b.point - a.point));
      }
      spacing = std::max(spacing, 0.5 / rings * std::fabs(b.point - a.point) * (1.0 + r / rho));
    }
    const double slope = std::max(std::fabs(a.tangent_dradius.w), std::fabs(b.tangent_dradius.w));
    if (slope < 1) swept = std::max(swept, r * (1.0 / std::sqrt(1.0 - slope * slope) - 1.0));
    contact = std::max(contact, r * slope);
  }
  return {facet + along + curve + swept, param + contact / mm_per_point + spacing, mm_per_point};
}

struct Agreement {
  CoverageComparison coverage;
  size_t both = 0, fiber_mismatch = 0, facing = 0, other_surface = 0;
  double max_depth_mm = 0, max_normal_error = 0, max_position_error = 0;
  // The largest position error beyond what the pixel's own depth error
  // explains (a hit d mm off along the ray is up to d / mm_per_point points
  // off along the fiber) and the parameters' difference.
  double position_excess = 0;
  uint32_t worst_x = 0, worst_y = 0;  // the pixel of the largest depth error
  double worst_cosine = 0;
  // Coverage agreement counting pixels both cover but at another part of
  // the surface (below) as disagreeing.
  double agreement() const {
    const size_t either = coverage.covered_a + coverage.covered_b - coverage.covered_both;
    return either ? double(coverage.covered_both - other_surface) / double(either) : 1.0;
  }
  std::string summary() const {
    return coverage.summary() + "; " + std::to_string(both) + " both, " + std::to_string(other_surface) +
           " on another part of the surface, " + std::to_string(fiber_mismatch) + " fibers differ, depth error " +
           std::to_string(max_depth_mm) + " mm on " + std::to_string(facing) + " facing pixels (at " +
           std::to_string(worst_x) + ", " + std::to_string(worst_y) + ", cos " + std::to_string(worst_cosine) +
           "), normal " + std::to_string(max_normal_error) + ", position " + std::to_string(max_position_error) +
           " (excess " + std::to_string(position_excess) + ")";
  }
};

// Surface values are compared where the reference surface faces the eye
// (|cos| >= kFacing between its normal and the ray): a facet within e of
// the surface along its own normal, which is within pi / vertices of the
// surface's, lies within e / cos(theta + pi / vertices) along the ray, so
// the depth error is taken back to the normal by that factor. At grazing
// pixels a faceted silhouette moves the hit along the ray without bound,
// which the coverage comparison measures instead; a hit more than a tube
// diameter away along the ray is another part of the surface (the pixel is
// at the silhouette of a fold in front: a helix's turns), counted as a
// coverage disagreement.
constexpr double kFacing = 0.7;

Agreement compareWithReference(const std::vector<shader::SurfaceTexel>& gpu, const TubeReferenceImage& ref,
                               const Camera& camera, int vertices, double max_radius, const Tolerance& tolerance) {
  const std::array<double, 16> view = viewMatrixD(camera);
  const glm::dvec3 forward(-view[2], -view[6], -view[10]);
  const double n = camera.near_mm, f = camera.far_mm;
  Agreement a;
  std::vector<uint8_t> got(gpu.size()), want(gpu.size());
  for (size_t i = 0; i < gpu.size(); ++i) {
    got[i] = gpu[i].depth < 1.0f;
    want[i] = ref.fiber[i] != shader::kNoFiberId;
    if (!got[i] || !want[i]) continue;
    ++a.both;
    EXPECT_EQ(gpu[i].source, shader::kSurfaceSourceTube);
    const uint32_t px = uint32_t(i % camera.width), py = uint32_t(i / camera.width);
    glm::dvec3 o, d;
    tubePixelRay(camera, px, py, o, d);
    const double z_gpu = n * f / (f - double(gpu[i].depth) * (f - n));
    const double along_ray = std::fabs(z_gpu / glm::dot(d, forward) - ref.distance[i]);
    if (along_ray > 2.0 * max_radius) {
      ++a.other_surface;
      continue;
    }
    if (gpu[i].fiber != ref.fiber[i]) ++a.fiber_mismatch;
    const double cosine = std::fabs(glm::dot(glm::dvec3(ref.normal[i]), d));
    if (cosine < kFacing) continue;
    ++a.facing;
    const std::array<float, 3> g = test::unpackTangent(gpu[i].normal);
    a.max_normal_error =
        std::max(a.max_normal_error, double(glm::distance(glm::vec3(g[0], g[1], g[2]), ref.normal[i])));
    const double position_error = std::fabs(gpu[i].position - ref.position[i]);
    a.max_position_error = std::max(a.max_position_error, position_error);
    a.position_excess = std::max(
        a.position_excess, position_error - tolerance.position_points - along_ray / tolerance.mm_per_point - 1e-3);
    const double facet_cosine = std::cos(std::acos(cosine) + std::numbers::pi / vertices);
    const double e = along_ray * facet_cosine;
    if (e > a.max_depth_mm) {
      a.max_depth_mm = e;
      a.worst_x = px;
      a.worst_y = py;
      a.worst_cosine = cosine;
    }
  }
  a.coverage = compareCoverage(got, want, camera.width, camera.height);
  return a;
}

std::string cameraName(const Camera& camera) {
  return "from (" + std::to_string(camera.eye[0]) + ", " + std::to_string(camera.eye[1]) + ", " +
         std::to_string(camera.eye[2]) + ")";
}

// The default tessellation against the reference: >= 98 % coverage
// agreement, silhouettes within a pixel, the same fibers, depth and the
// position along the fiber within the tolerance, normals within a facet's
// angle.
void expectMatchesReference(const Agreement& a, const Tolerance& tolerance, int vertices, const std::string& what) {
  EXPECT_GT(a.both, 250u) << what;
  EXPECT_GE(a.agreement(), 0.98) << what;
  EXPECT_LE(a.coverage.maxDistance(), 1.0) << what;
  EXPECT_EQ(a.fiber_mismatch, 0u) << what;
  EXPECT_LE(a.max_depth_mm, tolerance.surface_mm) << what << " (tolerance " << tolerance.surface_mm << " mm)";
  EXPECT_LE(a.position_excess, 0.0) << what << " (tolerance " << tolerance.position_points << " points)";
  EXPECT_LE(a.max_normal_error, 2.0 * std::sin(0.5 * std::numbers::pi / vertices)) << what;
}

TEST_F(GpuTubeTess, tessellatedTubesMatchTheRayCastReferenceOnCurvedTubes) {
  const RenderSettings defaults;
  for (const test::TubeScene& scene : test::tubeScenes()) {
    const TubeModel model = buildTubes(scene.tractogram, scene.options);
    const Tolerance tolerance = tessellationTolerance(model, defaults.tube_rings, defaults.tube_vertices);
    for (const Camera& camera : test::tubeSceneCameras(scene, 120, 90)) {
      const TubeReferenceImage ref = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
      FrameStats stats;
      const std::vector<shader::SurfaceTexel> got = draw(model, camera, {}, &stats);
      maybeWritePng("tess " + scene.name + " " + cameraName(camera), got, camera);
      const Agreement a = compareWithReference(got, ref, camera, defaults.tube_vertices, scene.max_radius, tolerance);
      const std::string what = scene.name + " " + cameraName(camera) + ": " + a.summary();
      expectMatchesReference(a, tolerance, defaults.tube_vertices, what);
      bool timed_keys = false, timed_texels = false;
      for (const PassTiming& p : stats.passes) {
        timed_keys |= p.name == "tube tess";
        timed_texels |= p.name == "tube tess texels";
        EXPECT_TRUE(isTubePass(p.name) || p.name.rfind("tube", 0) != 0) << p.name;
      }
      EXPECT_TRUE(timed_keys && timed_texels);
    }
  }
}

// The tube's own colour (per point, Hermite along the tube) and the
// fiber, position and normal against the compute ray caster's texels on
// the pixels both cover and the surface faces the eye: a colour channel
// differs by at most the colour's slope per point times the two texels'
// difference in position along the fiber, plus the 8-bit rounding of both.
TEST_F(GpuTubeTess, colourAlongTheTubeMatchesTheComputeRayCaster) {
  test::TubeScene scene = test::tubeScenes()[1];  // the S-curve of varying radius
  std::vector<float> rgb;
  const size_t points = scene.tractogram.pointsIn(0);
  for (size_t i = 0; i < points; ++i) {
    const float v = float(i) / float(points - 1);
    rgb.insert(rgb.end(), {v, 1.0f - v, 0.5f + 0.4f * std::sin(6.0f * v)});
  }
  scene.tractogram.per_point.push_back({"rgb", 3, "float32", rgb});
  scene.options.color.source = TubeColor::Source::PerPoint;
  scene.options.color.array = "rgb";
  const TubeModel model = buildTubes(scene.tractogram, scene.options);
  double slope_per_point = 0;  // largest |d colour / d point| over the nodes
  for (const shader::TubeSegment& s : model.segments) {
    const shader::TubeNode &a = model.nodes[s.node], &b = model.nodes[s.node + 1];
    const double mm_per_point = s.chord / std::max(1e-6, double(b.point - a.point));
    for (const shader::TubeNode* n : {&a, &b})
      for (int k = 0; k < 3; ++k) {
        const int8_t q = int8_t((n->color_slope >> (8 * k)) & 0xFFu);
        slope_per_point =
            std::max(slope_per_point, std::fabs(double(q) / 127.0 * shader::kTubeColorSlopeMax) * mm_per_point);
      }
  }
  for (const Camera& camera : test::tubeSceneCameras(scene, 120, 90)) {
    const std::vector<shader::SurfaceTexel> tess = draw(model, camera);
    GpuTubes tubes = uploadTubes(context(), model);
    std::vector<shader::SurfaceTexel> cast;
    try {
      FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, tubeRaycastStage(&tubes)});
      renderer.render(camera, RenderSettings(), GpuScene());
      cast = downloadSurface(context(), renderer.targets());
    } catch (...) {
      destroyTubes(context(), tubes);
      throw;
    }
    destroyTubes(context(), tubes);
    size_t compared = 0, coloured = 0;
    double worst = 0;
    for (size_t i = 0; i < tess.size(); ++i) {
      if (!(tess[i].depth < 1.0f && cast[i].depth < 1.0f)) continue;
      const std::array<float, 3> nc = test::unpackTangent(cast[i].normal);
      glm::dvec3 o, d;
      tubePixelRay(camera, uint32_t(i % camera.width), uint32_t(i / camera.width), o, d);
      if (std::fabs(glm::dot(glm::dvec3(nc[0], nc[1], nc[2]), d)) < kFacing) continue;
      ++compared;
      EXPECT_EQ(tess[i].fiber, cast[i].fiber);
      coloured += (tess[i].color >> 24) == 255u && (cast[i].color >> 24) == 255u;
      const double allowed = slope_per_point * std::fabs(tess[i].position - cast[i].position) + 2.0 / 255.0;
      for (int k = 0; k < 3; ++k) {
        const double ct = double((tess[i].color >> (8 * k)) & 0xFFu) / 255.0;
        const double cc = double((cast[i].color >> (8 * k)) & 0xFFu) / 255.0;
        worst = std::max(worst, std::fabs(ct - cc) - allowed);
      }
    }
    EXPECT_GT(compared, 100u) << cameraName(camera);
    EXPECT_EQ(coloured, compared) << cameraName(camera);
    EXPECT_LE(worst, 0.0) << cameraName(camera) << ": a channel off by " << worst << " beyond the bound";
  }
}

// tube_msaa 4 and 8: supersampled coverage (a pixel is the tube's when half
// its samples are covered, its texel the fragment nearest at most of them)
// against the reference's pixel centres: the two estimators differ on
// edge pixels only, so silhouettes within a pixel, disagreements no more
// than the reference's edge pixels, and the same surface bounds as one
// sample.
TEST_F(GpuTubeTess, supersampledCoverageMatchesTheReference) {
  for (const int samples : {4, 8}) {
    if ((context().limits().framebufferNoAttachmentsSampleCounts & uint32_t(samples)) == 0) {
      // Refused with a message, not drawn wrong.
      std::printf("tube-msaa %d: not among the device's framebufferNoAttachmentsSampleCounts: refused\n", samples);
      RenderSettings settings;
      settings.tube_msaa = samples;
      const test::TubeScene scene = test::tubeScenes()[0];
      const TubeModel model = buildTubes(scene.tractogram, scene.options);
      try {
        draw(model, test::tubeSceneCameras(scene, 32, 24)[0], {}, nullptr, settings);
        ADD_FAILURE() << "tube-msaa " << samples << " drawn on a device without it";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("tube-msaa"), std::string::npos) << e.what();
      }
      continue;
    }
    RenderSettings settings;
    settings.tube_msaa = samples;
    for (const test::TubeScene& scene : test::tubeScenes()) {
      const TubeModel model = buildTubes(scene.tractogram, scene.options);
      const Tolerance tolerance = tessellationTolerance(model, settings.tube_rings, settings.tube_vertices);
      const Camera camera = test::tubeSceneCameras(scene, 120, 90)[1];
      const std::vector<shader::SurfaceTexel> got = draw(model, camera, {}, nullptr, settings);
      const TubeReferenceImage reference = renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade);
      const Agreement a =
          compareWithReference(got, reference, camera, settings.tube_vertices, scene.max_radius, tolerance);
      const std::string what = std::to_string(samples) + " samples, " + scene.name + ": " + a.summary();
      EXPECT_GT(a.both, 250u) << what;
      // Only pixels on the reference's edges (covered next to uncovered, or
      // next to another fiber or another part of the surface, 4-neighbours,
      // either side) may go either way.
      const TubeReferenceImage& ref = reference;
      size_t edge = 0;
      for (uint32_t y = 0; y < camera.height; ++y)
        for (uint32_t x = 0; x < camera.width; ++x) {
          const size_t i = size_t(y) * camera.width + x;
          bool differs = false;
          const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
          for (int k = 0; k < 4; ++k) {
            const int nx = int(x) + dx[k], ny = int(y) + dy[k];
            if (nx < 0 || ny < 0 || nx >= int(camera.width) || ny >= int(camera.height)) continue;
            const size_t j = size_t(ny) * camera.width + size_t(nx);
            differs |=
                ref.fiber[i] != ref.fiber[j] || std::fabs(ref.distance[i] - ref.distance[j]) > 2.0 * scene.max_radius;
          }
          edge += differs;
        }
      const size_t either = a.coverage.covered_a + a.coverage.covered_b - a.coverage.covered_both;
      EXPECT_GE(a.agreement(), 1.0 - double(edge) / double(either)) << what << " (" << edge << " edge pixels)";
      EXPECT_LE(a.coverage.maxDistance(), 1.0) << what;
      EXPECT_EQ(a.fiber_mismatch, 0u) << what;
      EXPECT_LE(a.max_depth_mm, tolerance.surface_mm) << what;
      // An edge pixel's texel may come from a fragment off the pixel centre
      // (interpolated there from a triangle covering other samples): half
      // a pixel diagonal on screen, at the farthest hit, along the fiber.
      double farthest = 0;  // view distance (mm)
      const double n = camera.near_mm, f = camera.far_mm;
      for (const shader::SurfaceTexel& t : got)
        if (t.depth < 1.0f) farthest = std::max(farthest, n * f / (f - double(t.depth) * (f - n)));
      const double pixel_mm =
          2.0 * std::tan(0.5 * camera.fov_y_deg * std::numbers::pi / 180.0) / camera.height * farthest;
      EXPECT_LE(a.position_excess, 0.5 * std::sqrt(2.0) * pixel_mm / tolerance.mm_per_point) << what;
      EXPECT_LE(a.max_normal_error, 2.0 * std::sin(0.5 * std::numbers::pi / settings.tube_vertices)) << what;
    }
  }
}

// One renderer switching tube_msaa 1 -> 4 -> 1 between frames (the
// pipeline and the keys remade) gives each frame a fresh renderer's texels.
TEST_F(GpuTubeTess, switchingSamplesBetweenFramesGivesFreshFrames) {
  if ((context().limits().framebufferNoAttachmentsSampleCounts & 4u) == 0) GTEST_SKIP() << "no 4 samples";
  const test::TubeScene scene = test::tubeScenes()[0];
  const TubeModel model = buildTubes(scene.tractogram, scene.options);
  const Camera camera = test::tubeSceneCameras(scene, 64, 48)[1];
  RenderSettings one, four;
  four.tube_msaa = 4;
  const std::vector<shader::SurfaceTexel> fresh_one = draw(model, camera, {}, nullptr, one);
  const std::vector<shader::SurfaceTexel> fresh_four = draw(model, camera, {}, nullptr, four);
  GpuTubes tubes = uploadTubes(context(), model);
  try {
    FrameRenderer renderer(context(), camera.width, camera.height, {makeSetupStage, tubeTessellationStage(&tubes)});
    const RenderSettings* sequence[3] = {&one, &four, &one};
    const std::vector<shader::SurfaceTexel>* expected[3] = {&fresh_one, &fresh_four, &fresh_one};
    for (int f = 0; f < 3; ++f) {
      renderer.render(camera, *sequence[f], GpuScene());
      const std::vector<shader::SurfaceTexel> got = downloadSurface(context(), renderer.targets());
      ASSERT_EQ(got.size(), expected[f]->size());
      EXPECT_EQ(std::memcmp(got.data(), expected[f]->data(), got.size() * sizeof(got[0])), 0) << "frame " << f;
    }
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
  size_t differ = 0;
  for (size_t i = 0; i < fresh_one.size(); ++i) differ += (fresh_one[i].depth < 1.0f) != (fresh_four[i].depth < 1.0f);
  EXPECT_GT(differ, 0u) << "4 samples changed no pixel's coverage";
}

// Rings that twisted between nodes would pinch the tube (its cross-section
// a collapsed circle where the frame turns about the tangent): a helix of
// tight pitch and a 90-degree corner taken within two segments, both
// against the reference with the same tolerances.
TEST_F(GpuTubeTess, ringsDoNotTwistOnAHelixOrASharpCorner) {
  Tractogram t;
  std::vector<float> helix, corner;
  for (int i = 0; i <= 24; ++i) {
    const float a = float(i) * std::numbers::pi_v<float> / 6.0f;  // 30 degrees a point
    helix.insert(helix.end(), {2.0f * std::cos(a), 2.0f * std::sin(a), 0.25f * a - 3.0f});
  }
  for (int i = 0; i <= 4; ++i) corner.insert(corner.end(), {-7.0f + float(i), -4.0f, 1.0f});
  for (int i = 1; i <= 4; ++i) corner.insert(corner.end(), {-3.0f, -4.0f + float(i), 1.0f});
  t.addStreamline(helix.data(), helix.size() / 3);
  t.addStreamline(corner.data(), corner.size() / 3);
  TubeBuildOptions o;
  o.radius.radius = 0.45f;
  const TubeModel model = buildTubes(t, o);
  const RenderSettings defaults;
  const Tolerance tolerance = tessellationTolerance(model, defaults.tube_rings, defaults.tube_vertices);
  Bounds b = tractogramBounds(t);
  for (int k = 0; k < 3; ++k) {
    b.min[k] -= 0.45f;
    b.max[k] += 0.45f;
  }
  for (const Camera& camera :
       {fitCamera(b, {0, 0, 1}, {0, 1, 0}, 128, 96), fitCamera(b, {1, -0.5, 0.3}, {0, 0, 1}, 128, 96)}) {
    const std::vector<shader::SurfaceTexel> got = draw(model, camera);
    maybeWritePng("tess helix " + cameraName(camera), got, camera);
    const Agreement a = compareWithReference(got, renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade),
                                             camera, defaults.tube_vertices, 0.45, tolerance);
    expectMatchesReference(a, tolerance, defaults.tube_vertices,
                           "helix and corner " + cameraName(camera) + ": " + a.summary());
  }
}

// Back-patch and frustum culling, each alone and together, against none:
// the same texels, bit for bit (the close-up cameras put part of the tubes
// outside the frame).
TEST_F(GpuTubeTess, patchCullingChangesNoTexel) {
  for (const test::TubeScene& scene : test::tubeScenes()) {
    const TubeModel model = buildTubes(scene.tractogram, scene.options);
    for (const Camera& camera : test::tubeSceneCameras(scene, 96, 72)) {
      const std::vector<shader::SurfaceTexel> all = draw(model, camera, {false, false});
      for (const TubeTessOptions culling :
           {TubeTessOptions{true, false}, TubeTessOptions{false, true}, TubeTessOptions{}}) {
        const std::vector<shader::SurfaceTexel> culled = draw(model, camera, culling);
        ASSERT_EQ(culled.size(), all.size());
        size_t covered = 0, differ = 0;
        for (size_t i = 0; i < all.size(); ++i) {
          covered += all[i].depth < 1.0f;
          differ += std::memcmp(&culled[i], &all[i], sizeof(all[i])) != 0;
        }
        EXPECT_GT(covered, 100u) << scene.name;
        EXPECT_EQ(differ, 0u) << scene.name << " " << cameraName(camera) << ", back " << culling.back_patch_culling
                              << ", frustum " << culling.frustum_culling << ": " << covered << " covered";
      }
    }
  }
}

TEST_F(GpuTubeTess, aOnePointTubeIsASphere) {
  Tractogram t;
  const float one[] = {0, 0, 0};
  t.addStreamline(one, 1);
  TubeBuildOptions o;
  o.radius.radius = 2.0f;
  const TubeModel model = buildTubes(t, o);
  Camera camera;
  camera.eye = {3, 4, 30};
  camera.width = 64;
  camera.height = 64;
  camera.near_mm = 20;
  camera.far_mm = 40;
  const Agreement a =
      compareWithReference(draw(model, camera), renderReferenceTubes(model, camera, TubeReferenceMethod::Cascade),
                           camera, 8, 2.0, tessellationTolerance(model, 16, 8));
  EXPECT_GE(a.agreement(), 0.95) << a.summary();  // a disk of radius 7.9 px: 194 pixels
  EXPECT_LE(a.coverage.maxDistance(), 1.0) << a.summary();
  EXPECT_LE(a.max_depth_mm, 2.0 * (1.0 - std::cos(std::numbers::pi / 8))) << a.summary();
}

TEST_F(GpuTubeTess, anEmptyModelDrawsNothing) {
  const TubeModel empty = buildTubes(Tractogram(), {});
  Camera camera;
  camera.eye = {0, 0, 30};
  camera.width = 32;
  camera.height = 24;
  FrameStats stats;
  const std::vector<shader::SurfaceTexel> surface = draw(empty, camera, {}, &stats);
  for (const shader::SurfaceTexel& t : surface) ASSERT_EQ(t.depth, 1.0f);
  for (const PassTiming& p : stats.passes) EXPECT_NE(p.name, "tube tess");
  // And a model wholly behind the camera runs the passes and draws nothing.
  Tractogram t;
  const float xyz[] = {-1, 0, 40, 1, 0, 40, 2, 1, 41};
  t.addStreamline(xyz, 3);
  TubeBuildOptions o;
  o.radius.radius = 0.5f;
  const std::vector<shader::SurfaceTexel> behind = draw(buildTubes(t, o), camera, {}, &stats);
  for (const shader::SurfaceTexel& s : behind) ASSERT_EQ(s.depth, 1.0f);
  bool timed = false;
  for (const PassTiming& p : stats.passes) timed |= p.name == "tube tess";
  EXPECT_TRUE(timed);
}

}  // namespace
}  // namespace fibscope
