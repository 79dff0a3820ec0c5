// The SVO streamtubes on the device (src/svo/gpu): the radix sort against
// std::stable_sort, the GPU voxelisation (one slab and several) against
// the CPU reference, the tree from the GPU's leaves against the CPU tree,
// the memory check, and the ray tracing of straight tubes against a
// brute-force ray-capsule intersection over every segment and against
// Intel Embree's round linear curves. Validation layers on.
#include <gtest/gtest.h>

#if FIBSCOPE_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "gpu_test_context.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/frame_targets.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "svo/gpu/gpu_svo.h"
#include "svo/svo_build.h"
#include "svo/svo_reference.h"
#include "svo_test_scenes.h"

namespace fibscope {
namespace {

class GpuSvo_ : public test::GpuTest {};
using GpuSvoSort = GpuSvo_;
using GpuSvoBuild = GpuSvo_;
using GpuSvoTrace = GpuSvo_;

TEST_F(GpuSvoSort, radixSortMatchesStdStableSort) {
  std::mt19937 rng(7);
  // Up to 2^20 + 3 keys: 65,537 blocks' counts, past one scan chunk's
  // 1,024 and one level of chunks (the single-invocation scan this replaced
  // scrambled the order past 2^16 counts on lavapipe).
  for (const uint32_t n : {1u, 255u, 256u, 5000u, (1u << 20) + 3u}) {
    for (const uint32_t bits : {30u, 32u}) {
      if (n > 5000 && bits == 32) continue;  // the large case once (its time)
      std::vector<uint32_t> keys(n), values(n);
      for (uint32_t i = 0; i < n; ++i) {
        keys[i] = uint32_t(rng()) & (bits == 32 ? 0xFFFFFFFFu : ((1u << bits) - 1));
        if (i % 3 == 0) keys[i] &= 0xFFu;  // many equal keys: the stability shows
        values[i] = i;
      }
      std::vector<uint32_t> order(n);
      std::iota(order.begin(), order.end(), 0u);
      std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
      std::vector<uint32_t> want_keys(n);
      for (uint32_t i = 0; i < n; ++i) want_keys[i] = keys[order[i]];
      gpuRadixSort(context(), keys, values, bits);
      EXPECT_EQ(keys, want_keys) << n << " keys of " << bits << " bits";
      EXPECT_EQ(values, order) << n << " keys of " << bits << " bits";
    }
  }
}

// Leaves of the GPU and the CPU: the same codes except voxels whose |f|
// lies within float rounding of the band's edge, distances within 1e-5 mm.
void expectSameLeaves(const std::vector<SvoLeaf>& gpu, const std::vector<SvoLeaf>& cpu, float band) {
  size_t i = 0, j = 0, edge = 0;
  float max_error = 0;
  while (i < gpu.size() || j < cpu.size()) {
    if (j == cpu.size() || (i < gpu.size() && gpu[i].code < cpu[j].code)) {
      EXPECT_GT(std::fabs(gpu[i].distance), band - 1e-5f) << "leaf " << gpu[i].code << " only on the GPU";
      ++edge, ++i;
    } else if (i == gpu.size() || cpu[j].code < gpu[i].code) {
      EXPECT_GT(std::fabs(cpu[j].distance), band - 1e-5f) << "leaf " << cpu[j].code << " only on the CPU";
      ++edge, ++j;
    } else {
      max_error = std::max(max_error, std::fabs(gpu[i].distance - cpu[j].distance));
      ++i, ++j;
    }
  }
  EXPECT_LE(max_error, 1e-5f);
  EXPECT_LE(edge, cpu.size() / 1000 + 2);
}

TEST_F(GpuSvoBuild, voxelisationMatchesTheCpuReferenceInOneSlabAndInMany) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.1f);
  ASSERT_GE(grid.side(), 64u);
  GpuTubes tubes = uploadTubes(context(), model);
  const std::vector<SvoLeaf> cpu = voxelizeSvoLeaves(model, grid);
  try {
    SvoGpuBuildStats one, many;
    const std::vector<SvoLeaf> a = voxelizeSvoLeavesGpu(context(), model, tubes, grid, {}, &one);
    SvoGpuBuildOptions slabs;
    slabs.field_budget_bytes = uint64_t(grid.side()) * grid.side() * 4 * 5;  // 5 planes a slab
    const std::vector<SvoLeaf> b = voxelizeSvoLeavesGpu(context(), model, tubes, grid, slabs, &many);
    EXPECT_EQ(one.slabs, 1u);
    EXPECT_GT(many.slabs, 10u);
    expectSameLeaves(a, cpu, grid.band());
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].code, b[i].code);
      EXPECT_EQ(a[i].distance, b[i].distance);
    }
    // A leaf estimate too small: the build reruns with the exact count.
    EXPECT_LE(one.retries, 1u);
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
}

TEST_F(GpuSvoBuild, treeFromTheGpuIsTheCpuTree) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  GpuTubes tubes = uploadTubes(context(), model);
  SvoTree gpu_tree;
  try {
    gpu_tree = buildSvoGpu(context(), model, tubes, grid);
  } catch (...) {
    destroyTubes(context(), tubes);
    throw;
  }
  destroyTubes(context(), tubes);
  const SvoTree cpu_tree = buildSvoCpu(model, grid);
  ASSERT_EQ(gpu_tree.leaves, cpu_tree.leaves);
  EXPECT_EQ(gpu_tree.decoration, cpu_tree.decoration);
  ASSERT_EQ(gpu_tree.nodes.size(), cpu_tree.nodes.size());
  for (size_t i = 0; i < gpu_tree.nodes.size(); ++i) {
    EXPECT_EQ(gpu_tree.nodes[i].ref, cpu_tree.nodes[i].ref) << i;
    EXPECT_NEAR(gpu_tree.nodes[i].distance, cpu_tree.nodes[i].distance, 1e-5f) << i;
  }
  EXPECT_GT(gpu_tree.leaves_over_4, 10u);
}

TEST_F(GpuSvoBuild, aBuildPastTheMemoryLimitFailsBeforeAllocatingAndNamesTheSize) {
  const TubeModel model = buildTubes(test::denseSvoBundle(), test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.05f);
  GpuTubes tubes = uploadTubes(context(), model);
  SvoGpuBuildOptions o;
  o.memory_limit_bytes = 1 << 20;
  std::string message;
  try {
    buildSvoGpu(context(), model, tubes, grid, o);
  } catch (const Error& e) {
    message = e.what();
  }
  destroyTubes(context(), tubes);
  EXPECT_NE(message.find("needs about"), std::string::npos) << message;
  EXPECT_NE(message.find("MB"), std::string::npos) << message;
  EXPECT_NE(message.find("choose a larger voxel"), std::string::npos) << message;
}

// Frames of the SVO stage alone (one build, one renderer; the cameras of
// one size): their surface targets.
std::vector<std::vector<shader::SurfaceTexel>> traceOnGpu(const gpu::VulkanContext& context, const TubeModel& model,
                                                          const SvoGrid& grid, const std::vector<Camera>& cameras,
                                                          SvoTree* tree_out = nullptr) {
  GpuTubes tubes = uploadTubes(context, model);
  GpuSvo svo;
  std::vector<std::vector<shader::SurfaceTexel>> surfaces;
  try {
    const SvoTree tree = buildSvoGpu(context, model, tubes, grid);
    if (tree_out) *tree_out = tree;
    svo = uploadSvo(context, tree);
    FrameRenderer renderer(context, cameras[0].width, cameras[0].height,
                           {makeSetupStage, svoTraceStage(&svo, &tubes)});
    for (const Camera& camera : cameras) {
      renderer.render(camera, RenderSettings(), GpuScene());
      surfaces.push_back(downloadSurface(context, renderer.targets()));
    }
  } catch (...) {
    destroySvo(context, svo);
    destroyTubes(context, tubes);
    throw;
  }
  destroySvo(context, svo);
  destroyTubes(context, tubes);
  return surfaces;
}

// View-axis distance of a clip depth (camera.cpp's projection).
double viewZ(const Camera& c, double depth) { return c.near_mm * c.far_mm / (c.far_mm - depth * (c.far_mm - c.near_mm)); }

struct TraceAgreement {
  size_t either = 0, disagree = 0, both = 0, fiber_mismatch = 0;
  double max_depth_mm = 0;
  std::string summary() const {
    return std::to_string(both) + " pixels both, " + std::to_string(disagree) + " of " + std::to_string(either) +
           " covered by one only, " + std::to_string(fiber_mismatch) + " other fiber, depth error " +
           std::to_string(max_depth_mm) + " mm";
  }
};

// `ref_fiber` kNoFiberId where the reference misses; `ref_z` its view-axis distance.
TraceAgreement compareTrace(const std::vector<shader::SurfaceTexel>& gpu, const std::vector<uint32_t>& ref_fiber,
                            const std::vector<double>& ref_z, const Camera& camera) {
  TraceAgreement a;
  for (size_t i = 0; i < gpu.size(); ++i) {
    const bool hg = gpu[i].depth < 1.0f, hr = ref_fiber[i] != shader::kNoFiberId;
    if (!hg && !hr) continue;
    ++a.either;
    if (hg != hr) {
      ++a.disagree;
      continue;
    }
    ++a.both;
    EXPECT_EQ(gpu[i].source, shader::kSurfaceSourceSvo);
    if (gpu[i].fiber != ref_fiber[i]) ++a.fiber_mismatch;
    a.max_depth_mm = std::max(a.max_depth_mm, std::fabs(viewZ(camera, gpu[i].depth) - ref_z[i]));
  }
  return a;
}

TEST_F(GpuSvoTrace, straightTubesMatchBruteForceRayCapsuleOnADenseBundle) {
  const Tractogram t = test::denseSvoBundle();
  const TubeModel model = buildTubes(t, test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  // Oblique and from above (small frames: the reference is O(pixels x segments)).
  const std::array<double, 3> views[] = {{0.3, -1.0, 0.6}, {0.1, 0.1, 1.0}};
  std::vector<Camera> cameras;
  for (const auto& v : views) cameras.push_back(test::svoCamera(t, v[0], v[1], v[2], 80, 64));
  SvoTree tree;
  const auto frames = traceOnGpu(context(), model, grid, cameras, &tree);
  // The seed's 4-nearest lists would lose tubes here.
  EXPECT_GT(tree.leaves_over_4, 10u);
  for (size_t view_index = 0; view_index < cameras.size(); ++view_index) {
    const auto& v = views[view_index];
    const Camera& camera = cameras[view_index];
    const std::vector<shader::SurfaceTexel>& gpu = frames[view_index];
    const TubeReferenceImage ref = renderBruteForceCapsules(model, camera);
    const std::array<double, 16> view = viewMatrixD(camera);
    const glm::dvec3 forward(-view[2], -view[6], -view[10]);
    std::vector<double> ref_z(ref.distance.size());
    for (size_t i = 0; i < ref_z.size(); ++i) {
      glm::dvec3 o, d;
      tubePixelRay(camera, uint32_t(i % camera.width), uint32_t(i / camera.width), o, d);
      ref_z[i] = ref.distance[i] * glm::dot(d, forward);
    }
    const TraceAgreement a = compareTrace(gpu, ref.fiber, ref_z, camera);
    const std::string what = "view (" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " +
                             std::to_string(v[2]) + "): " + a.summary();
    std::printf("brute force, %s\n", what.c_str());
    EXPECT_GT(a.both, 500u) << what;
    EXPECT_EQ(a.disagree, 0u) << what;
    EXPECT_EQ(a.fiber_mismatch, 0u) << what;
    EXPECT_LE(a.max_depth_mm, 1e-4) << what;
    // Every fiber the reference shows, the SVO shows (none lost).
    std::set<uint32_t> want, got;
    for (size_t i = 0; i < gpu.size(); ++i) {
      if (ref.fiber[i] != shader::kNoFiberId) want.insert(ref.fiber[i]);
      if (gpu[i].depth < 1.0f) got.insert(gpu[i].fiber);
    }
    EXPECT_EQ(got, want) << what;
  }
}

// Curved tubes (svo-curved) against a finely subdivided straight-tube
// reference: each cubic as 32 straight capsules, brute-force ray-capsule
// in double. Tolerances: the reference's own error is the sagitta of its
// sub-chords (chords of up to 2.1 mm / 32 on arcs of radius >= 3 mm:
// (0.066 mm)^2 / (8 * 3 mm) = 2e-4 mm), the sphere tracing's hit
// tolerance kSvoHitEpsilon * voxel (1.5e-4 mm at the scene's 0.15 mm
// voxel), so along the surface normal within 1e-3 mm; along the ray that
// is divided by |cos| of the ray's angle to the normal, large at grazing
// silhouette pixels, so depths within 0.02 mm (2/15 of a voxel) on every
// pixel. Coverage and fiber ids differ at most on grazing pixels
// (<= 1 % and <= 0.5 %; measured: none). The GPU curved voxelisation is
// the CPU's.
TEST_F(GpuSvoTrace, curvedTubesMatchASubdividedStraightTubeReference) {
  const Tractogram t = test::curvedSvoBundle();
  const TubeModel model = buildTubes(t, test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f, true);
  const TubeModel fine = test::subdivideCurvedTubes(model, 32);
  {
    GpuTubes tubes = uploadTubes(context(), model);
    std::vector<SvoLeaf> gpu;
    try {
      gpu = voxelizeSvoLeavesGpu(context(), model, tubes, grid);
    } catch (...) {
      destroyTubes(context(), tubes);
      throw;
    }
    destroyTubes(context(), tubes);
    expectSameLeaves(gpu, voxelizeSvoLeaves(model, grid), grid.band());
  }
  const std::array<double, 3> views[] = {{0.3, -1.0, 0.6}, {0.1, 0.1, 1.0}};
  std::vector<Camera> cameras;
  for (const auto& v : views) cameras.push_back(test::svoCamera(t, v[0], v[1], v[2], 64, 48));
  const auto frames = traceOnGpu(context(), model, grid, cameras);
  const auto straight_frames = traceOnGpu(context(), model, chooseSvoGrid(model, 0.0f), cameras);
  for (size_t view_index = 0; view_index < cameras.size(); ++view_index) {
    const auto& v = views[view_index];
    const Camera& camera = cameras[view_index];
    const std::vector<shader::SurfaceTexel>& gpu = frames[view_index];
    const TubeReferenceImage ref = renderBruteForceCapsules(fine, camera);
    const std::array<double, 16> view = viewMatrixD(camera);
    const glm::dvec3 forward(-view[2], -view[6], -view[10]);
    std::vector<double> ref_z(ref.distance.size());
    for (size_t i = 0; i < ref_z.size(); ++i) {
      glm::dvec3 o, d;
      tubePixelRay(camera, uint32_t(i % camera.width), uint32_t(i / camera.width), o, d);
      ref_z[i] = ref.distance[i] * glm::dot(d, forward);
    }
    const TraceAgreement a = compareTrace(gpu, ref.fiber, ref_z, camera);
    // The straight tubes against the same reference: they differ (the
    // scene's curvature shows), so the agreement above is the curve's.
    const TraceAgreement s = compareTrace(straight_frames[view_index], ref.fiber, ref_z, camera);
    const std::string what = "view (" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " +
                             std::to_string(v[2]) + "): " + a.summary() + "; straight: " + s.summary();
    std::printf("curved vs 32 capsules per segment, %s\n", what.c_str());
    EXPECT_GT(a.both, 250u) << what;
    EXPECT_LE(double(a.disagree), 0.01 * double(a.either)) << what;
    EXPECT_LE(double(a.fiber_mismatch), 0.005 * double(a.both)) << what;
    EXPECT_LE(a.max_depth_mm, 0.02) << what;
    EXPECT_GT(s.disagree + s.fiber_mismatch, a.disagree + a.fiber_mismatch) << what;
    // Along the normal within 1e-3 mm; normals point away from the centre
    // line (the ray meets the front) and agree with the reference's.
    double normal_error = 0, worst_normal_angle = 1;
    for (size_t i = 0; i < gpu.size(); ++i)
      if (gpu[i].depth < 1.0f && ref.fiber[i] != shader::kNoFiberId) {
        glm::dvec3 o, d;
        tubePixelRay(camera, uint32_t(i % camera.width), uint32_t(i / camera.width), o, d);
        const glm::dvec3 n(unpackUnitVector(gpu[i].normal));
        EXPECT_LE(glm::dot(n, d), 0.05) << i;
        const double dt = std::fabs(viewZ(camera, gpu[i].depth) - ref_z[i]) / glm::dot(d, forward);
        normal_error = std::max(normal_error, dt * std::fabs(glm::dot(glm::dvec3(ref.normal[i]), d)));
        worst_normal_angle = std::min(worst_normal_angle, glm::dot(n, glm::dvec3(ref.normal[i])));
      }
    std::printf("  along the normal within %.2e mm, normals' cosine >= %.4f\n", normal_error, worst_normal_angle);
    EXPECT_LE(normal_error, 1e-3) << what;
    EXPECT_GE(worst_normal_angle, 0.99) << what;
  }
}

#if FIBSCOPE_HAVE_EMBREE
// Embree's round linear curves of constant radius: a segment's cone with
// spheres at both ends, which for one radius is the capsule.
struct EmbreeFrame {
  std::vector<uint32_t> fiber;
  std::vector<double> z;
};
EmbreeFrame traceEmbree(const TubeModel& model, const Camera& camera) {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene scene = rtcNewScene(device);
  // Segments of length > 0 as curves (geometry 0), zero-length ones
  // (one-point fibers) as Embree's spheres (geometry 1): Embree draws
  // nothing for a curve segment of length 0.
  std::vector<uint32_t> curve_segment, sphere_segment;
  for (uint32_t s = 0; s < model.segments.size(); ++s) {
    const SvoCapsule c = svoCapsule(model, model.segments[s]);
    (c.a == c.b ? sphere_segment : curve_segment).push_back(s);
  }
  if (!curve_segment.empty()) {
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    const size_t n = curve_segment.size();
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 2 * n));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), n));
    for (size_t k = 0; k < n; ++k) {
      const SvoCapsule c = svoCapsule(model, model.segments[curve_segment[k]]);
      const float v[8] = {c.a.x, c.a.y, c.a.z, c.radius, c.b.x, c.b.y, c.b.z, c.radius};
      std::copy(v, v + 8, vertices + 8 * k);
      indices[k] = unsigned(2 * k);  // no shared vertices: every segment has both end spheres
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene, g, 0);
    rtcReleaseGeometry(g);
  }
  if (!sphere_segment.empty()) {
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                                 4 * sizeof(float), sphere_segment.size()));
    for (size_t k = 0; k < sphere_segment.size(); ++k) {
      const SvoCapsule c = svoCapsule(model, model.segments[sphere_segment[k]]);
      const float v[4] = {c.a.x, c.a.y, c.a.z, c.radius};
      std::copy(v, v + 4, vertices + 4 * k);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(scene, g, 1);
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(scene);
  EmbreeFrame frame;
  frame.fiber.assign(size_t(camera.width) * camera.height, shader::kNoFiberId);
  frame.z.assign(frame.fiber.size(), 0.0);
  const std::array<double, 16> view = viewMatrixD(camera);
  const glm::dvec3 forward(-view[2], -view[6], -view[10]);
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  for (uint32_t py = 0; py < camera.height; ++py)
    for (uint32_t px = 0; px < camera.width; ++px) {
      glm::dvec3 o, d;
      tubePixelRay(camera, px, py, o, d);
      RTCRayHit rh{};
      rh.ray.org_x = float(o.x), rh.ray.org_y = float(o.y), rh.ray.org_z = float(o.z);
      rh.ray.dir_x = float(d.x), rh.ray.dir_y = float(d.y), rh.ray.dir_z = float(d.z);
      rh.ray.tnear = 0.0f;
      rh.ray.tfar = INFINITY;
      rh.ray.mask = ~0u;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene, &ctx, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
      const size_t i = size_t(py) * camera.width + px;
      const uint32_t seg = rh.hit.geomID == 0 ? curve_segment[rh.hit.primID] : sphere_segment[rh.hit.primID];
      frame.fiber[i] = model.segments[seg].fiber;
      frame.z[i] = double(rh.ray.tfar) * glm::dot(d, forward);
    }
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  return frame;
}
#endif

// Skips, naming the reason, where the build has no Embree.
#if FIBSCOPE_HAVE_EMBREE
#define REQUIRE_EMBREE()
#else
#define REQUIRE_EMBREE() GTEST_SKIP() << "Embree not installed (Debian's libembree-dev): no independent reference"
#endif

TEST_F(GpuSvoTrace, straightTubesAgreeWithEmbreeRoundLinearCurves) {
  REQUIRE_EMBREE();
#if FIBSCOPE_HAVE_EMBREE
  const Tractogram t = test::denseSvoBundle();
  const TubeModel model = buildTubes(t, test::svoTubeOptions(0.3f));
  const SvoGrid grid = chooseSvoGrid(model, 0.0f);
  const Camera camera = test::svoCamera(t, 0.4, -1.0, 0.5, 128, 96);
  const std::vector<shader::SurfaceTexel> gpu = traceOnGpu(context(), model, grid, {camera})[0];
  const EmbreeFrame ref = traceEmbree(model, camera);
  size_t covered = 0, agree = 0;
  double max_depth = 0;
  for (size_t i = 0; i < gpu.size(); ++i) {
    const uint32_t g = gpu[i].depth < 1.0f ? gpu[i].fiber : shader::kNoFiberId;
    if (g == shader::kNoFiberId && ref.fiber[i] == shader::kNoFiberId) continue;
    ++covered;
    if (g != ref.fiber[i]) {
      if (std::getenv("SVO_DEBUG"))
        std::printf("px %zu gpu %u z %.6f embree %u z %.6f\n", i, g, g == shader::kNoFiberId ? 0.0 : viewZ(camera, gpu[i].depth),
                    ref.fiber[i], ref.z[i]);
      continue;
    }
    ++agree;
    max_depth = std::max(max_depth, std::fabs(viewZ(camera, gpu[i].depth) - ref.z[i]));
  }
  std::printf("Embree: %zu of %zu covered pixels the same fiber, depth within %.2e mm\n", agree, covered, max_depth);
  ASSERT_GT(covered, 1000u);  // measured: 1,601
  EXPECT_GE(double(agree) / double(covered), 0.999) << agree << " of " << covered;
  EXPECT_LE(max_depth, 1e-3) << agree << " of " << covered;
#endif
}

// The benchmarks' measurement: builds the SVO of `model` on the GPU and
// returns the trace pass's GPU time of the second frame (the first creates
// the pipelines).
// `wall_ms` (may be null): the host clock around that frame (on a CPU
// device the trustworthy figure).
double buildAndTraceMs(gpu::VulkanContext& context, const TubeModel& model, const SvoGrid& grid, const Camera& camera,
                       SvoTree& tree, SvoGpuBuildStats& st, double* wall_ms = nullptr) {
  GpuTubes tubes = uploadTubes(context, model);
  GpuSvo svo;
  double trace_ms = 0;
  try {
    tree = buildSvoGpu(context, model, tubes, grid, {}, &st);
    svo = uploadSvo(context, tree);
    FrameRenderer renderer(context, camera.width, camera.height, {makeSetupStage, svoTraceStage(&svo, &tubes)});
    renderer.render(camera, RenderSettings(), GpuScene());
    const auto t0 = std::chrono::steady_clock::now();
    const FrameStats frame = renderer.render(camera, RenderSettings(), GpuScene());
    if (wall_ms) *wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (const PassTiming& p : frame.passes)
      if (p.name == "svo trace") trace_ms += p.ms;
  } catch (...) {
    destroySvo(context, svo);
    destroyTubes(context, tubes);
    throw;
  }
  destroySvo(context, svo);
  destroyTubes(context, tubes);
  return trace_ms;
}

// svo-straight beside svo-curved on the same phantom subsets, build and
// image (FIBSCOPE_SVO_BENCH=1): the trace pass's GPU timestamps (second
// frame), the builds' wall time. Step 2 mm, so the curves bow.
TEST_F(GpuSvoTrace, benchmarkStraightAgainstCurvedWhenAsked) {
  if (!std::getenv("FIBSCOPE_SVO_BENCH")) GTEST_SKIP() << "set FIBSCOPE_SVO_BENCH=1 to measure";
  std::printf("| fibers | segments | voxel mm | grid | pipeline | leaves | references | voxelise s | build s | "
              "trace ms |\n");
  for (const uint64_t fibers : {50u, 200u}) {
    PhantomOptions po;
    po.streamlines = fibers;
    po.step_mm = 2.0;
    const Tractogram t = readAllStreamlines(*openPhantom(po));
    const TubeModel model = buildTubes(t, test::svoTubeOptions(0.5f));
    const Camera camera = test::svoCamera(t, 0.4, -1.0, 0.5, 256, 192);
    for (const bool curved : {false, true}) {
      const SvoGrid grid = chooseSvoGrid(model, 0.0f, curved);
      SvoGpuBuildStats st;
      SvoTree tree;
      const double trace_ms = buildAndTraceMs(context(), model, grid, camera, tree, st);
      std::printf("| %llu | %zu | %.3f | %u^3 | %s | %zu | %zu | %.1f | %.1f | %.1f |\n",
                  static_cast<unsigned long long>(fibers), model.segments.size(), grid.voxel, grid.side(),
                  curved ? "svo-curved" : "svo-straight", tree.leaves, tree.references, st.voxelize_s, st.tree_s,
                  trace_ms);
      std::fflush(stdout);
    }
  }
}

// Figures for docs/BENCHMARKS.md, not a check: runs only with
// FIBSCOPE_SVO_BENCH=1 (prints a table; nothing timed is asserted).
// Phantom subsets at 1 mm steps, radius 0.5 mm, 256 x 192 px; the SVO's
// build times (host clock around each step), memory, its trace pass (GPU
// timestamps) and Embree's build + trace of the same image on one thread
// of the same CPU.
TEST_F(GpuSvoTrace, benchmarkAgainstEmbreeWhenAsked) {
  if (!std::getenv("FIBSCOPE_SVO_BENCH")) GTEST_SKIP() << "set FIBSCOPE_SVO_BENCH=1 to measure";
  REQUIRE_EMBREE();
#if FIBSCOPE_HAVE_EMBREE
  using Clock = std::chrono::steady_clock;
  std::printf("| fibers | segments | streamline buffer MB | voxel mm | grid | leaves | >4 | nodes MB | decoration MB | "
              "voxelise s | sort s | build s | SVO trace ms | Embree build+trace ms |\n");
  for (const uint64_t fibers : {50u, 200u, 800u}) {
    PhantomOptions po;
    po.streamlines = fibers;
    po.step_mm = 1.0;
    const Tractogram t = readAllStreamlines(*openPhantom(po));
    const TubeModel model = buildTubes(t, test::svoTubeOptions(0.5f));
    const SvoGrid grid = chooseSvoGrid(model, 0.0f);
    const Camera camera = test::svoCamera(t, 0.4, -1.0, 0.5, 256, 192);
    SvoGpuBuildStats st;
    SvoTree tree;
    const double trace_ms = buildAndTraceMs(context(), model, grid, camera, tree, st);
    const auto e0 = Clock::now();
    traceEmbree(model, camera);
    const double embree_ms = std::chrono::duration<double, std::milli>(Clock::now() - e0).count();
    std::printf("| %llu | %zu | %.3f | %.3f | %u^3 | %zu | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | %.1f | %.1f |\n",
                static_cast<unsigned long long>(fibers), model.segments.size(), double(model.deviceBytes()) / 1e6,
                grid.voxel, grid.side(), tree.leaves, tree.leaves_over_4, double(tree.nodeBytes()) / 1e6,
                double(tree.decorationBytes()) / 1e6, st.voxelize_s, st.sort_s, st.tree_s, trace_ms, embree_ms);
  }
#endif
}

// The seed's table 2 on this device (figures, not a check): runs only with
// FIBSCOPE_SVO_TABLE2=A.tck,B.tck,... (scripts/svo_table1.sh keeps its
// bundles with KEEP=1). Per file: svo-straight and svo-curved built by the
// voxel rule and traced at FIBSCOPE_SVO_TABLE2_SIZE (1920x1080) with
// FIBSCOPE_SVO_TABLE2_RADIUS (0.5 mm), the trace pass's GPU timestamps
// (second frame), and Embree's scene build plus one ray per pixel of the
// same image on one thread of the same CPU (host clock): a ratio from one
// run.
TEST_F(GpuSvoTrace, table2WhenAsked) {
  const char* files = std::getenv("FIBSCOPE_SVO_TABLE2");
  if (!files) GTEST_SKIP() << "set FIBSCOPE_SVO_TABLE2=A.tck,B.tck to measure";
  REQUIRE_EMBREE();
#if FIBSCOPE_HAVE_EMBREE
  using Clock = std::chrono::steady_clock;
  uint32_t width = 1920, height = 1080;
  if (const char* size = std::getenv("FIBSCOPE_SVO_TABLE2_SIZE"))
    ASSERT_EQ(std::sscanf(size, "%ux%u", &width, &height), 2) << size;
  const char* radius_text = std::getenv("FIBSCOPE_SVO_TABLE2_RADIUS");
  const float radius = radius_text ? std::strtof(radius_text, nullptr) : 0.5f;
  std::printf("| file | segments | size | svo-straight trace ms (frame wall ms) | svo-curved trace ms (frame wall ms) | "
              "Embree build + trace ms | straight frame wall / Embree |\n");
  std::string list = files;
  for (size_t at = 0; at <= list.size();) {
    const size_t comma = std::min(list.find(',', at), list.size());
    const std::string path = list.substr(at, comma - at);
    at = comma + 1;
    if (path.empty()) continue;
    const Tractogram t = readAllStreamlines(*openTractogram(path));
    const TubeModel model = buildTubes(t, test::svoTubeOptions(radius));
    const Camera camera = test::svoCamera(t, 0.4, -1.0, 0.5, width, height);
    double ms[2] = {0, 0}, wall[2] = {0, 0};
    for (const bool curved : {false, true}) {
      SvoGpuBuildStats st;
      SvoTree tree;
      ms[curved] = buildAndTraceMs(context(), model, chooseSvoGrid(model, 0.0f, curved, svoMemoryLimit(context())),
                                   camera, tree, st, &wall[curved]);
    }
    const auto e0 = Clock::now();
    traceEmbree(model, camera);
    const double embree_ms = std::chrono::duration<double, std::milli>(Clock::now() - e0).count();
    std::printf("| %s | %zu | %ux%u | %.1f (%.1f) | %.1f (%.1f) | %.1f | %.2f |\n", path.c_str(), model.segments.size(),
                width, height, ms[0], wall[0], ms[1], wall[1], embree_ms, wall[0] / embree_ms);
    std::fflush(stdout);
  }
#endif
}

}  // namespace
}  // namespace fibscope
