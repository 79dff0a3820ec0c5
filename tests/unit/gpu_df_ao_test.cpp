// Distance-field AO and soft shadows (issue 16 item 4): the GPU field
// against the brute-force distance to the capsules (exact at voxel
// centres, within the trilinear bound between them); the GPU AO and shadow
// factors per pixel against the CPU evaluation of the same formulas on the
// same field at the pixel's G-buffer position and normal; physically
// checkable scenes (a tube on a wall of tubes is darker than an isolated
// one; a tube behind another towards the light is shadowed, an isolated one
// is not); and ao-method ssao giving the same image with the
// distance-field stage in the frame as without it. Validation layers on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "gpu_test_context.h"
#include "svo_test_scenes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "shared/distance_field.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "shared/shade_push.h"
#include "svo/distance_field.h"
#include "svo/gpu/gpu_distance_field.h"
#include "svo/gpu/gpu_svo.h"

namespace fibscope {
namespace {

class GpuDfAo : public test::GpuTest {};

// The tubes' field on the device, released with the test.
struct FieldOwner {
  const gpu::VulkanContext& context;
  GpuTubes tubes;
  GpuDistanceField field;
  GpuSvo svo;
  ~FieldOwner() {
    destroySvo(context, svo);
    destroyDistanceField(context, field);
    destroyTubes(context, tubes);
  }
};

// glsl/distance_field.glsl's dfPixelPoint on the host, in float from the
// same camera block and texels.
bool pixelPoint(const shader::CameraBlock& cam, const shader::GBufferTexel& g, const shader::SurfaceTexel& s,
                uint32_t x, uint32_t y, glm::vec3& p, glm::vec3& n) {
  if (g.fiber == shader::kNoFiberId || g.fiber == shader::kNoFiberObject) return false;
  const glm::vec3 right(cam.view[0].x, cam.view[1].x, cam.view[2].x), up(cam.view[0].y, cam.view[1].y, cam.view[2].y),
      back(cam.view[0].z, cam.view[1].z, cam.view[2].z);
  const float p00 = glm::dot(glm::vec3(cam.view_projection[0].x, cam.view_projection[1].x, cam.view_projection[2].x), right);
  const float p11 = glm::dot(glm::vec3(cam.view_projection[0].y, cam.view_projection[1].y, cam.view_projection[2].y), up);
  const glm::vec2 ndc = (glm::vec2(float(x), float(y)) + 0.5f) / glm::vec2(cam.viewport.x, cam.viewport.y) * 2.0f - 1.0f;
  const glm::vec3 to_eye = -glm::normalize((ndc.x / p00) * right + (ndc.y / p11) * up - back);
  const float nr = cam.depth_range.x, fr = cam.depth_range.y;
  const float z = nr * fr / (fr - g.depth * (fr - nr));
  p = glm::vec3(cam.eye.x, cam.eye.y, cam.eye.z) - to_eye * (z / glm::dot(to_eye, back));
  if ((g.segment & shader::kGBufferSurface) != 0u) {
    if (s.source == shader::kSurfaceSourceSlice) return false;
    n = unpackUnitVector(s.normal);
    if (glm::dot(n, to_eye) < 0.0f) n = -n;
  } else {
    const glm::vec3 t = unpackUnitVector(g.tangent);
    const glm::vec3 towards = to_eye - glm::dot(to_eye, t) * t;
    const float len = glm::length(towards);
    n = len > shader::kShadeNormalParallelEps ? towards / len : to_eye;
  }
  return true;
}

glm::vec3 headlight(const shader::CameraBlock& cam) {
  const glm::vec3 lv =
      glm::normalize(glm::vec3(shader::kShadeLightViewX, shader::kShadeLightViewY, shader::kShadeLightViewZ));
  return lv.x * glm::vec3(cam.view[0].x, cam.view[1].x, cam.view[2].x) +
         lv.y * glm::vec3(cam.view[0].y, cam.view[1].y, cam.view[2].y) +
         lv.z * glm::vec3(cam.view[0].z, cam.view[1].z, cam.view[2].z);
}

// One frame of `lines` as SVO tubes with the distance-field stage.
struct DfFrame {
  std::vector<shader::GBufferTexel> gbuffer;
  std::vector<shader::SurfaceTexel> surface;
  std::vector<float> ao, shadow, field;
  std::vector<uint8_t> color;
  DistanceFieldGrid grid;
  shader::CameraBlock camera;
};

DfFrame renderDfFrame(const gpu::VulkanContext& context, const Tractogram& lines, float radius, float voxel,
                      const Camera& camera, const RenderSettings& settings, bool with_df_stage = true) {
  const TubeModel model = buildTubes(lines, test::svoTubeOptions(radius));
  const TractogramUpload upload = uploadTractogram(context, lines, "lines");
  const GpuRawTractogram raw = GpuRawTractogram::upload(context, lines, "lines");
  FieldOwner owner{context, uploadTubes(context, model), {}, {}};
  owner.svo = uploadSvo(context, buildSvoGpu(context, model, owner.tubes, chooseSvoGrid(model, 0.0f)));
  owner.field = buildDistanceFieldGpu(context, owner.tubes, chooseDistanceFieldGrid(model, voxel));
  FrameStageList stages = withSvoStage(standardFrameStages(), &owner.svo, &owner.tubes);
  if (with_df_stage) stages = withDistanceFieldStage(std::move(stages), &owner.field);
  FrameRenderer renderer(context, camera.width, camera.height, std::move(stages));
  renderer.render(camera, settings, GpuScene(&upload.dataset, &raw));
  DfFrame f;
  const GpuFrameTargets& t = renderer.targets();
  f.gbuffer = downloadGBuffer(context, t);
  f.surface = downloadSurface(context, t);
  f.color = downloadColor(context, t);
  f.ao.resize(t.pixels());
  f.shadow.resize(t.pixels());
  gpu::downloadFromBuffer(context, t.ao, f.ao.data(), f.ao.size() * sizeof(float));
  gpu::downloadFromBuffer(context, t.ao_blur, f.shadow.data(), f.shadow.size() * sizeof(float));
  f.field = downloadDistanceField(context, owner.field);
  f.grid = owner.field.grid;
  f.camera = makeCameraBlock(camera, settings.line_width_px);
  return f;
}

RenderSettings dfSettings() {
  RenderSettings s;
  s.ao_method = AoMethod::Df;
  s.df_shadows = true;
  s.orientation_labels = false;
  return s;
}

TEST_F(GpuDfAo, fieldMatchesBruteForceCapsulesWithinTheTrilinearBound) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const DistanceFieldGrid grid = chooseDistanceFieldGrid(model, 0.25f);
  ASSERT_LE(grid.bytes(), 64ull << 20);
  FieldOwner owner{context(), uploadTubes(context(), model), {}, {}};
  owner.field = buildDistanceFieldGpu(context(), owner.tubes, grid);
  const std::vector<float> field = downloadDistanceField(context(), owner.field);
  ASSERT_EQ(field.size(), grid.voxels());

  // Voxel centres: the capsules' distance (float, the same formula), clamped.
  size_t inside = 0, checked = 0;
  float worst_centre = 0.0f;
  for (uint32_t z = 0; z < grid.size.z; z += 3)
    for (uint32_t y = 0; y < grid.size.y; y += 2)
      for (uint32_t x = 0; x < grid.size.x; ++x) {
        const float want = bruteForceDistance(model, grid.center(x, y, z), grid.band);
        const float got = field[(size_t(z) * grid.size.y + y) * grid.size.x + x];
        worst_centre = std::max(worst_centre, std::abs(got - want));
        inside += want < 0.0f;
        ++checked;
      }
  EXPECT_LE(worst_centre, 1e-5f) << checked << " centres";
  EXPECT_GT(inside, 10u);

  // Between centres: a trilinear blend of a 1-Lipschitz field differs from
  // the field at p by at most the blend of the corners' distances to p.
  std::mt19937 rng(7);
  const glm::vec3 lo = grid.origin + grid.voxel, hi = grid.origin + (glm::vec3(grid.size) - 1.0f) * grid.voxel;
  std::uniform_real_distribution<float> ux(lo.x, hi.x), uy(lo.y, hi.y), uz(lo.z, hi.z);
  int near_tubes = 0;
  for (int k = 0; k < 4000; ++k) {
    const glm::vec3 p(ux(rng), uy(rng), uz(rng));
    const float want = bruteForceDistance(model, p, grid.band);
    if (want >= grid.band) continue;
    near_tubes += want < 0.5f;
    const glm::vec3 g = (p - grid.origin) / grid.voxel - 0.5f;
    const glm::vec3 f = g - glm::floor(g);
    float bound = 0.0f;
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? 1.0f : 0.0f, (c & 2) ? 1.0f : 0.0f, (c & 4) ? 1.0f : 0.0f);
      const glm::vec3 w = glm::mix(1.0f - f, f, corner);
      bound += w.x * w.y * w.z * glm::length((corner - f) * grid.voxel);
    }
    const float got = sampleDistanceField(grid, field, p);
    ASSERT_LE(std::abs(got - want), bound + 1e-5f) << "at (" << p.x << ", " << p.y << ", " << p.z << ")";
  }
  EXPECT_GT(near_tubes, 50);
  std::printf("field %ux%ux%u at %.3f mm: centres within %.2g mm of the capsules' distance\n", grid.size.x,
              grid.size.y, grid.size.z, grid.voxel, worst_centre);
}

TEST_F(GpuDfAo, aoAndShadowPerPixelMatchTheCpuFormulasOnTheSameField) {
  const Tractogram lines = test::denseSvoBundle(16);
  const Camera camera = test::svoCamera(lines, 0.3, -1.0, 0.6, 96, 72);
  RenderSettings settings = dfSettings();
  settings.df_ao_strength = 1.5f;
  const DfFrame f = renderDfFrame(context(), lines, 0.3f, 0.25f, camera, settings);
  const float delta = f.grid.voxel, k = settings.df_ao_strength;
  const glm::vec3 l = headlight(f.camera);
  const glm::vec3 eye(f.camera.eye.x, f.camera.eye.y, f.camera.eye.z);
  size_t covered = 0, occluded = 0, shadowed = 0;
  float worst_ao = 0.0f, worst_shadow = 0.0f;
  for (uint32_t y = 0; y < camera.height; ++y)
    for (uint32_t x = 0; x < camera.width; ++x) {
      const size_t i = size_t(y) * camera.width + x;
      glm::vec3 p, n;
      if (!pixelPoint(f.camera, f.gbuffer[i], f.surface[i], x, y, p, n)) continue;
      ++covered;
      // Float error of the position (depth linearised and scaled along the
      // ray: ~1e-6 relative) moves every sample as much; the field's slope
      // is at most 1, the sum's weights 1/2 + 1/4 + ... < 1.
      const float position_error = 4e-6f * glm::length(p - eye) + 1e-5f;
      const float ao = distanceFieldAo(f.grid, f.field, p, n, uint32_t(settings.df_ao_steps), delta, k);
      const float ao_tolerance = k / delta * position_error + 1e-5f;
      worst_ao = std::max(worst_ao, std::abs(ao - f.ao[i]) / ao_tolerance);
      occluded += ao < 0.9f;
      // The shadow's ratio d / t changes by k_s position_error / t, t >= the
      // start offset; a step's length by as much, which moves later samples
      // (a few steps' worth).
      const float s = shader::kDfShadowStartVoxels * f.grid.voxel;
      const float shadow = distanceFieldShadow(f.grid, f.field, p, n, l, settings.df_shadow_softness);
      const float shadow_tolerance = settings.df_shadow_softness * 8.0f * position_error / s + 1e-4f;
      worst_shadow = std::max(worst_shadow, std::abs(shadow - f.shadow[i]) / shadow_tolerance);
      shadowed += shadow < 0.9f;
    }
  std::printf("%zu covered pixels (%zu with AO < 0.9, %zu with shadow < 0.9): largest error over tolerance AO %.3f, "
              "shadow %.3f\n",
              covered, occluded, shadowed, worst_ao, worst_shadow);
  EXPECT_GT(covered, 300u);
  EXPECT_GT(occluded, 30u) << "the bundle should occlude itself";
  EXPECT_GT(shadowed, 10u) << "the bundle should shadow itself";
  EXPECT_LE(worst_ao, 1.0f) << "largest AO error over its tolerance";
  EXPECT_LE(worst_shadow, 1.0f) << "largest shadow error over its tolerance";
}

// A straight fiber from a to b in `points` steps.
void addLine(Tractogram& t, glm::vec3 a, glm::vec3 b, int points) {
  std::vector<float> xyz;
  for (int i = 0; i < points; ++i) {
    const glm::vec3 p = glm::mix(a, b, float(i) / float(points - 1));
    xyz.insert(xyz.end(), {p.x, p.y, p.z});
  }
  t.addStreamline(xyz.data(), xyz.size() / 3);
}

// The mean of `values` over the pixels of fiber `fiber`.
double fiberMean(const DfFrame& f, const std::vector<float>& values, uint32_t fiber, size_t& pixels) {
  double sum = 0;
  pixels = 0;
  for (size_t i = 0; i < f.gbuffer.size(); ++i)
    if (f.gbuffer[i].fiber == fiber && (f.gbuffer[i].segment & shader::kGBufferSurface) != 0u) {
      sum += values[i];
      ++pixels;
    }
  return pixels ? sum / double(pixels) : 0.0;
}

TEST_F(GpuDfAo, aTubeLyingOnAWallOfTubesIsDarkerThanAnIsolatedOne) {
  const float r = 1.0f;
  Tractogram lines;
  for (int k = 0; k < 12; ++k) {  // the wall: tubes side by side in z = 0
    const float y = -11.0f + 2.0f * r * float(k);
    addLine(lines, {-12.0f, y, 0.0f}, {12.0f, y, 0.0f}, 13);
  }
  const uint32_t on_wall = 12, isolated = 13;
  addLine(lines, {-8.0f, 0.0f, 2.0f * r + 0.2f}, {8.0f, 0.0f, 2.0f * r + 0.2f}, 9);
  addLine(lines, {-8.0f, 0.0f, 16.0f}, {8.0f, 0.0f, 16.0f}, 9);
  Camera camera;
  camera.eye = {0, -60, 12};
  camera.target = {0, 0, 8};
  camera.up = {0, 0, 1};
  camera.width = 96;
  camera.height = 96;
  RenderSettings settings = dfSettings();
  settings.df_shadows = false;
  const DfFrame f = renderDfFrame(context(), lines, r, 0.5f, camera, settings);
  size_t n_wall = 0, n_isolated = 0;
  const double ao_wall = fiberMean(f, f.ao, on_wall, n_wall);
  const double ao_isolated = fiberMean(f, f.ao, isolated, n_isolated);
  ASSERT_GT(n_wall, 100u);
  ASSERT_GT(n_isolated, 100u);
  std::printf("mean AO: tube on the wall %.3f (%zu px), isolated %.3f (%zu px)\n", ao_wall, n_wall, ao_isolated,
              n_isolated);
  EXPECT_GT(ao_isolated, 0.9) << "an isolated tube hardly occludes itself";
  EXPECT_LT(ao_wall, ao_isolated - 0.05) << "on the wall " << ao_wall << ", isolated " << ao_isolated;
}

TEST_F(GpuDfAo, aTubeBehindAnotherTowardsTheLightIsShadowedAnIsolatedOneIsNot) {
  const float r = 1.0f;
  // The camera looks down -z with right = +x and up = +y, so the headlight
  // is normalize(kShadeLightView*) in world space too.
  const glm::vec3 l =
      glm::normalize(glm::vec3(shader::kShadeLightViewX, shader::kShadeLightViewY, shader::kShadeLightViewZ));
  const glm::vec3 axis = glm::normalize(glm::vec3(-l.y, l.x, 0.0f));  // across l's image direction: l . axis = 0
  const glm::vec3 occluder = 6.0f * l;  // tube B: A moved 6 mm towards the light
  const glm::vec3 far_off = 20.0f * axis;  // tube C: A moved along its own axis, in the open
  Tractogram lines;
  const uint32_t shaded = 0, open = 2;
  addLine(lines, -6.0f * axis, 6.0f * axis, 7);
  addLine(lines, occluder - 6.0f * axis, occluder + 6.0f * axis, 7);
  addLine(lines, far_off - 6.0f * axis, far_off + 6.0f * axis, 7);
  Camera camera;
  const glm::vec3 centre = 0.5f * far_off + 0.5f * occluder;
  camera.target = {centre.x, centre.y, 0};
  camera.eye = {centre.x, centre.y, 70};
  camera.up = {0, 1, 0};
  camera.width = 128;
  camera.height = 96;
  const DfFrame f = renderDfFrame(context(), lines, r, 0.5f, camera, dfSettings());
  ASSERT_NEAR(glm::dot(headlight(f.camera), l), 1.0f, 1e-5f);
  // The pixels of A and C facing the light (n . l > 0.8: around the line
  // of the surface nearest the light, which B's shadow covers on A).
  double shaded_min = 1.0, open_min = 1.0;
  size_t shaded_pixels = 0, open_pixels = 0;
  for (uint32_t y = 0; y < camera.height; ++y)
    for (uint32_t x = 0; x < camera.width; ++x) {
      const size_t i = size_t(y) * camera.width + x;
      glm::vec3 p, n;
      if (!pixelPoint(f.camera, f.gbuffer[i], f.surface[i], x, y, p, n) || glm::dot(n, l) < 0.8f) continue;
      // Away from the tubes' round ends.
      const float along = glm::dot(p - (f.gbuffer[i].fiber == open ? far_off : glm::vec3(0.0f)), axis);
      if (std::abs(along) > 4.0f) continue;
      if (f.gbuffer[i].fiber == shaded) {
        shaded_min = std::min<double>(shaded_min, f.shadow[i]);
        ++shaded_pixels;
      } else if (f.gbuffer[i].fiber == open) {
        open_min = std::min<double>(open_min, f.shadow[i]);
        ++open_pixels;
      }
    }
  ASSERT_GT(shaded_pixels, 20u);
  ASSERT_GT(open_pixels, 20u);
  size_t n_shaded = 0, n_open = 0;
  const double shaded_mean = fiberMean(f, f.shadow, shaded, n_shaded), open_mean = fiberMean(f, f.shadow, open, n_open);
  std::printf("shadow facing the light: behind B min %.3f, in the open min %.3f; means %.3f, %.3f\n", shaded_min,
              open_min, shaded_mean, open_mean);
  EXPECT_LT(shaded_min, 0.2) << "B's umbra on A";
  EXPECT_GT(open_min, 0.95) << "an isolated tube is unshadowed where it faces the light";
  EXPECT_LT(shaded_mean, open_mean - 0.1) << "A " << shaded_mean << ", C " << open_mean;
}

TEST_F(GpuDfAo, ssaoMethodGivesTheSameImageWithTheDistanceFieldStageInTheFrame) {
  const Tractogram lines = test::denseSvoBundle(16);
  const Camera camera = test::svoCamera(lines, 0.3, -1.0, 0.6, 96, 72);
  RenderSettings settings;
  settings.orientation_labels = false;
  ASSERT_EQ(settings.ao_method, AoMethod::Ssao);
  ASSERT_TRUE(settings.ssao);
  const DfFrame with = renderDfFrame(context(), lines, 0.3f, 0.25f, camera, settings, true);
  const DfFrame without = renderDfFrame(context(), lines, 0.3f, 0.25f, camera, settings, false);
  EXPECT_EQ(with.color, without.color);
  // And df is not the same image (the stage does run then).
  const DfFrame df = renderDfFrame(context(), lines, 0.3f, 0.25f, camera, dfSettings(), true);
  EXPECT_NE(df.color, without.color);
}

}  // namespace
}  // namespace fibscope
