// The mesh fiblet pipelines (fibscope issue 18 item 2; fiblets paper 3.3;
// src/render/gpu/fiblet_mesh_pass.h): VK_EXT_mesh_shader only.
//
// Suites named Device* carry the ctest label `device` (tests/CMakeLists.txt,
// DESIGN.md section 8): they need a real GPU feature and say SKIPPED with
// the reason ("VK_EXT_mesh_shader not supported by <device>") elsewhere,
// e.g. on lavapipe. Where they run they check, validation layers on, against
// independent references:
//   - the CPU reference rasteriser of the raw polylines: >= 98 % of the
//     covered pixels of each image within 1 px of a covered pixel of the
//     other (as the geometry pipeline's test);
//   - the geometry pipeline (the same fiblets, the same line rasteriser and
//     fragment shader): mesh-serial decodes in the geometry shader's order,
//     so the same points, and the parallel prefix differs by rounding only;
//   - culling none against frustum and two-phase, LoD off: the same
//     coverage over an orbit, a jump and a zoom, something culled;
//   - far-view LoD: the compute pipeline's LoD raster draws the same one
//     segment per fiblet;
//   - the fiber filter: dropped fibers are not drawn.
// Runnable everywhere (label gpu / unit): the extension enabled exactly
// where the device has it, the pipelines refused before anything is made
// where it lacks it, in one line with exit 2 on the command line, and the
// task and mesh SPIR-V embedded of the right stage (the build runs
// spirv-val on it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu/shader_library.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/fiblet_mesh_pass.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/lines_pass.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/render_config.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::gbufferMask;
using test::renderPhantom;

constexpr uint32_t kSize = 160;

// The fraction of covered pixels (of A and of B together) that lie within
// `radius` px of a covered pixel of the other image.
double fractionWithin(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b, double radius) {
  const std::vector<double> to_a = squaredDistanceToCovered(a, kSize, kSize);
  const std::vector<double> to_b = squaredDistanceToCovered(b, kSize, kSize);
  size_t covered = 0, near = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i]) {
      ++covered;
      near += to_b[i] <= radius * radius;
    }
    if (b[i]) {
      ++covered;
      near += to_a[i] <= radius * radius;
    }
  }
  return covered > 0 ? double(near) / double(covered) : 1.0;
}

// `mask` with a frame of kBorder px cleared.
constexpr uint32_t kBorder = 8;
std::vector<uint8_t> interior(std::vector<uint8_t> mask) {
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x)
      if (x < kBorder || y < kBorder || x >= kSize - kBorder || y >= kSize - kBorder) mask[size_t(y) * kSize + x] = 0;
  return mask;
}

RenderSettings plainSettings(RenderPipeline pipeline, CullingMode culling, float width) {
  RenderSettings s;
  s.pipeline = pipeline;
  s.culling = culling;
  s.line_width_px = width;
  s.lod_pixels = 0;  // LoD has a test of its own
  s.ssao = false;
  return s;
}

const RenderPipeline kMeshPipelines[] = {RenderPipeline::Mesh, RenderPipeline::MeshSerial};
std::string nameOf(RenderPipeline p) { return std::string(renderPipelineName(p)); }

struct View {
  const char* name;
  Camera camera;
};

class DeviceMeshPipeline : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    if (!context().meshShader().enabled)
      GTEST_SKIP() << "VK_EXT_mesh_shader not supported by " << context().info().name;
    const std::string why = fibletMeshRefusal(context(), RenderPipeline::Mesh);
    if (!why.empty()) GTEST_SKIP() << why;
    fibers_ = renderPhantom(400, 5);
    bounds_ = tractogramBounds(fibers_);
    upload_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers_, "phantom"));
    views_ = {{"sagittal", standardView(bounds_, StandardView::Sagittal, kSize, kSize)},
              {"coronal", standardView(bounds_, StandardView::Coronal, kSize, kSize)},
              {"axial", standardView(bounds_, StandardView::Axial, kSize, kSize)},
              {"oblique-close", orbitCamera(bounds_, 37, 23, kSize, kSize, 0.45)}};
  }
  void TearDown() override {
    upload_.reset();  // before the device goes
    test::GpuTest::TearDown();
  }
  const GpuDataset& dataset() const { return upload_->dataset; }

  std::vector<shader::GBufferTexel> render(FrameRenderer& renderer, const Camera& camera,
                                           const RenderSettings& settings, const GpuScene& scene,
                                           FrameStats* stats = nullptr) {
    const FrameStats s = renderer.render(camera, settings, scene);
    if (stats) *stats = s;
    return downloadGBuffer(context(), renderer.targets());
  }

  Tractogram fibers_;
  Bounds bounds_;
  std::unique_ptr<TractogramUpload> upload_;
  std::vector<View> views_;
};

TEST_F(DeviceMeshPipeline, meshAndMeshSerialCoverTheCpuReference) {
  FrameRenderer renderer(context(), kSize, kSize);
  for (const RenderPipeline pipeline : kMeshPipelines) {
    for (float requested : {1.0f, 3.0f}) {
      const float width = linesDrawnWidth(context(), requested);  // 1 without wideLines
      if (requested > 1.0f && width == 1.0f) continue;
      for (const View& view : views_) {
        SCOPED_TRACE(nameOf(pipeline) + " " + view.name + ", width " + std::to_string(width));
        const std::vector<uint8_t> reference = rasterizeReference(fibers_, view.camera, width).coverageMask();
        FrameStats stats;
        const auto texels = render(renderer, view.camera, plainSettings(pipeline, CullingMode::None, requested),
                                   GpuScene{&dataset()}, &stats);
        const std::vector<uint8_t> mask = gbufferMask(texels);
        const CoverageComparison c = compareCoverage(mask, reference, kSize, kSize);
        const double within = fractionWithin(mask, reference, 1.0);
        std::printf("[ DEVICE   ] %s %s w%.0f: vs reference %s, within 1 px %.4f; %.3f ms\n", nameOf(pipeline).c_str(),
                    view.name, width, c.summary().c_str(), within, stats.gpu_ms);
        ASSERT_GT(c.covered_b, kSize * kSize / 20) << "the view shows the phantom: " << c.summary();
        EXPECT_EQ(stats.fiblets_drawn, stats.fiblets_total);
        // The check: >= 98 % of the covered pixels within 1 px.
        EXPECT_GE(within, 0.98) << c.summary();
        // The device's lines against the capsule rule, bounded as the
        // geometry pipeline's are (gpu_fiblet_graphics_test).
        EXPECT_LE(c.max_distance_a_to_b, 1.5) << c.summary();
        EXPECT_LE(c.max_distance_b_to_a, 3.0) << c.summary();
      }
    }
  }
}

TEST_F(DeviceMeshPipeline, meshAndMeshSerialDrawWhatTheGeometryPipelineDraws) {
  const VkPhysicalDeviceFeatures& f = context().enabledFeatures();
  if (!f.geometryShader) GTEST_SKIP() << context().info().name << " has no geometry shaders to compare with";
  FrameRenderer renderer(context(), kSize, kSize);
  std::vector<View> views = views_;
  views.push_back({"very-close", orbitCamera(bounds_, 37, 23, kSize, kSize, 0.04)});
  for (const RenderPipeline pipeline : kMeshPipelines) {
    for (const View& view : views) {
      SCOPED_TRACE(nameOf(pipeline) + " " + view.name);
      const auto geometry = render(renderer, view.camera, plainSettings(RenderPipeline::Geometry, CullingMode::None, 1.0f),
                                   GpuScene{&dataset()});
      const auto drawn = render(renderer, view.camera, plainSettings(pipeline, CullingMode::None, 1.0f), GpuScene{&dataset()});
      // Inside a frame of kBorder px: Mesa 25's lavapipe drops the last
      // pixels (up to 5) of mesh-shader lines that leave the viewport,
      // where its geometry-shader lines, the CPU reference and the compute
      // pipeline agree (measured in the very-close view: 29 of 7973 px, all
      // within 5 px of the edge; mesh-serial's vertices are bit for bit the
      // geometry shader's, and every interior pixel matched).
      const CoverageComparison c =
          compareCoverage(interior(gbufferMask(drawn)), interior(gbufferMask(geometry)), kSize, kSize);
      size_t both = 0, same_fiber = 0, same_segment = 0;
      for (size_t i = 0; i < drawn.size(); ++i) {
        if (drawn[i].fiber == shader::kNoFiberId || geometry[i].fiber == shader::kNoFiberId) continue;
        ++both;
        if (drawn[i].fiber != geometry[i].fiber) continue;
        ++same_fiber;
        same_segment += drawn[i].segment == geometry[i].segment;
      }
      std::printf("[ DEVICE   ] %s %s vs geometry: %s; of %zu both, same fiber %zu, same segment %zu\n",
                  nameOf(pipeline).c_str(), view.name, c.summary().c_str(), both, same_fiber, same_segment);
      ASSERT_GT(c.covered_b, 200u);
      // The same lines through the same rasteriser: the points differ by
      // float rounding at most (none for mesh-serial, the geometry shader's
      // decode order), the primitive order within a draw may differ (depth
      // ties). Nearly every pixel agrees, none is far off.
      EXPECT_GE(c.agreement, pipeline == RenderPipeline::MeshSerial ? 0.999 : 0.99) << c.summary();
      EXPECT_LE(c.maxDistance(), 1.5) << c.summary();
      EXPECT_GE(double(same_fiber), 0.97 * double(both));
      EXPECT_GE(double(same_segment), 0.95 * double(same_fiber));
    }
  }
}

TEST_F(DeviceMeshPipeline, frustumAndTwoPhaseCullingKeepTheCoverageOfDrawingEveryFiblet) {
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  // An orbit of a few frames (two-phase learns from the last), a jump and a
  // zoom in (the frustum culls part of the phantom).
  const View views[] = {{"orbit 0", orbitCamera(bounds_, 30, 20, kSize, kSize, 1.0)},
                        {"orbit 1", orbitCamera(bounds_, 31.14, 20, kSize, kSize, 1.0)},
                        {"orbit 2", orbitCamera(bounds_, 32.28, 20, kSize, kSize, 1.0)},
                        {"jump", orbitCamera(bounds_, 92.28, 20, kSize, kSize, 1.0)},
                        {"zoomed", orbitCamera(bounds_, 93.42, 20, kSize, kSize, 0.25)}};
  for (const RenderPipeline pipeline : kMeshPipelines) {
    for (CullingMode mode : {CullingMode::Frustum, CullingMode::TwoPhase}) {
      bool culled_some = false;
      for (const View& view : views) {
        SCOPED_TRACE(nameOf(pipeline) + " " + std::string(cullingModeName(mode)) + " " + view.name);
        FrameStats none_stats, stats;
        const auto none = render(reference, view.camera, plainSettings(pipeline, CullingMode::None, 2.0f),
                                 GpuScene{&dataset()}, &none_stats);
        const auto drawn = render(culled, view.camera, plainSettings(pipeline, mode, 2.0f), GpuScene{&dataset()}, &stats);
        const CoverageComparison c = compareCoverage(gbufferMask(none), gbufferMask(drawn), kSize, kSize);
        size_t fiber_diff = 0;
        for (size_t i = 0; i < none.size(); ++i)
          fiber_diff += none[i].fiber != shader::kNoFiberId && drawn[i].fiber != shader::kNoFiberId &&
                        none[i].fiber != drawn[i].fiber;
        std::printf("[ DEVICE   ] %s %s %s: %s; other fiber %zu; drawn %llu of %llu\n", nameOf(pipeline).c_str(),
                    cullingModeName(mode).data(), view.name, c.summary().c_str(), fiber_diff,
                    (unsigned long long)stats.fiblets_drawn, (unsigned long long)stats.fiblets_total);
        ASSERT_GT(c.covered_a, 0u);
        // Conservative culling: the same pixels (fibers may differ at depth
        // ties only: the task workgroups' order is the device's).
        EXPECT_EQ(c.covered_a, c.covered_b) << c.summary();
        EXPECT_EQ(c.covered_both, c.covered_a) << c.summary();
        EXPECT_LE(fiber_diff, c.covered_a / 100);
        EXPECT_EQ(none_stats.fiblets_drawn, none_stats.fiblets_total);
        EXPECT_EQ(stats.fiblets_lod, 0u);  // LoD off here
        EXPECT_LE(stats.fiblets_drawn, stats.fiblets_total);
        culled_some |= stats.fiblets_drawn < stats.fiblets_total;
      }
      EXPECT_TRUE(culled_some) << "something is culled";
    }
  }
}

TEST_F(DeviceMeshPipeline, farViewLodDrawsTheComputePipelinesOneSegmentPerFiblet) {
  FrameRenderer renderer(context(), kSize, kSize);
  const Camera camera = orbitCamera(bounds_, 30, 20, kSize, kSize, 1.0);
  for (const RenderPipeline pipeline : kMeshPipelines) {
    SCOPED_TRACE(nameOf(pipeline));
    // Every fiblet is far: one segment each.
    RenderSettings lod = plainSettings(pipeline, CullingMode::Frustum, 1.0f);
    lod.lod_pixels = 4096.0f;  // the setting's largest
    RenderSettings compute = lod;
    compute.pipeline = RenderPipeline::Compute;
    FrameStats mesh_stats, compute_stats;
    const auto drawn = render(renderer, camera, lod, GpuScene{&dataset()}, &mesh_stats);
    const auto reference = render(renderer, camera, compute, GpuScene{&dataset()}, &compute_stats);
    const std::vector<uint8_t> a = gbufferMask(drawn), b = gbufferMask(reference);
    const CoverageComparison c = compareCoverage(a, b, kSize, kSize);
    std::printf("[ DEVICE   ] %s LoD vs compute LoD: %s; LoD %llu (compute %llu) of %llu\n", nameOf(pipeline).c_str(),
                c.summary().c_str(), (unsigned long long)mesh_stats.fiblets_lod,
                (unsigned long long)compute_stats.fiblets_lod, (unsigned long long)mesh_stats.fiblets_total);
    ASSERT_GT(c.covered_b, 200u);
    // The same cull (shared GLSL): the same fiblets go to LoD.
    EXPECT_EQ(mesh_stats.fiblets_lod, compute_stats.fiblets_lod);
    EXPECT_EQ(mesh_stats.fiblets_drawn, compute_stats.fiblets_drawn);
    EXPECT_GT(mesh_stats.fiblets_lod, 0u);
    // Lines against capsules of the same segments (as the coverage test).
    EXPECT_GE(fractionWithin(a, b, 1.0), 0.98) << c.summary();
  }
}

TEST_F(DeviceMeshPipeline, filteredFibersAreNotDrawn) {
  FrameRenderer renderer(context(), kSize, kSize);
  const Camera& camera = views_[1].camera;
  const uint32_t fibers = dataset().block().fiber_count;
  std::vector<uint32_t> words((fibers + 31) / 32, 0x55555555u);  // even fibers kept
  gpu::Buffer& kept = buffer(words.size() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
  gpu::uploadToBuffer(context(), kept, words.data(), words.size() * sizeof(uint32_t));
  for (const RenderPipeline pipeline : kMeshPipelines) {
    for (CullingMode culling : {CullingMode::None, CullingMode::Frustum, CullingMode::TwoPhase}) {
      SCOPED_TRACE(nameOf(pipeline) + " " + std::string(cullingModeName(culling)));
      GpuScene scene{&dataset()};
      const auto all = render(renderer, camera, plainSettings(pipeline, culling, 1.0f), scene);
      scene.kept_bits = kept.address;
      const auto filtered = render(renderer, camera, plainSettings(pipeline, culling, 1.0f), scene);
      size_t odd_before = 0, odd_after = 0, drawn = 0;
      for (size_t i = 0; i < all.size(); ++i) {
        odd_before += all[i].fiber != shader::kNoFiberId && all[i].fiber % 2 == 1;
        if (filtered[i].fiber == shader::kNoFiberId) continue;
        ++drawn;
        odd_after += filtered[i].fiber % 2 == 1;
      }
      EXPECT_GT(odd_before, 100u);
      EXPECT_GT(drawn, 100u);
      EXPECT_EQ(odd_after, 0u);
    }
  }
}

// Runs on every device (lavapipe included): the extension is enabled
// exactly where the device has it, with the EXT's guaranteed limits, and
// where it is missing the pipelines are refused before anything is made.
class GpuMeshSupport : public test::GpuTest {};

TEST_F(GpuMeshSupport, meshShadersAreEnabledWhereTheDeviceHasThemAndRefusedElsewhere) {
  const gpu::MeshShaderSupport& mesh = context().meshShader();
  std::printf("[ GPU      ] %s: VK_EXT_mesh_shader %s, enabled %s\n", context().info().name.c_str(),
              context().info().mesh_shader ? "listed" : "not listed", mesh.enabled ? "yes" : "no");
  if (mesh.enabled) {
    EXPECT_TRUE(context().info().mesh_shader);
    EXPECT_NE(mesh.cmdDrawMeshTasks, nullptr);
    // VK_EXT_mesh_shader's required minimums.
    EXPECT_GE(mesh.properties.maxMeshOutputVertices, 256u);
    EXPECT_GE(mesh.properties.maxMeshOutputPrimitives, 256u);
    EXPECT_GE(mesh.properties.maxMeshWorkGroupInvocations, 128u);
    EXPECT_GE(mesh.properties.maxTaskPayloadSize, 16384u);
    for (const RenderPipeline p : kMeshPipelines) EXPECT_EQ(fibletMeshRefusal(context(), p), "") << nameOf(p);
    return;
  }
  EXPECT_EQ(mesh.cmdDrawMeshTasks, nullptr);
  for (const RenderPipeline p : kMeshPipelines) {
    SCOPED_TRACE(nameOf(p));
    const std::string why = fibletMeshRefusal(context(), p);
    EXPECT_NE(why.find("VK_EXT_mesh_shader not supported by " + context().info().name), std::string::npos) << why;
    EXPECT_EQ(std::count(why.begin(), why.end(), '\n'), 0) << why;
    EXPECT_THROW(createFibletMeshPass(context(), p), Error);
    // A frame asks for it: refused in the stage's check, nothing recorded.
    const Tractogram fibers = renderPhantom(20, 3);
    const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
    FrameRenderer renderer(context(), 32, 32);
    const Camera camera = standardView(tractogramBounds(fibers), StandardView::Axial, 32, 32);
    EXPECT_THROW(renderer.render(camera, plainSettings(p, CullingMode::TwoPhase, 1.0f), GpuScene{&upload.dataset}),
                 Error);
  }
}

// The task and mesh shaders embedded in the program are SPIR-V modules of
// the right execution model (TaskEXT 5364, MeshEXT 5365); spirv-val checked
// them at build time (cmake/fibscope_shaders.cmake).
uint32_t entryPointModel(std::span<const uint32_t> words) {
  for (size_t i = 5; i < words.size();) {
    const uint32_t length = words[i] >> 16, opcode = words[i] & 0xffffu;
    if (length == 0) break;
    if (opcode == 15 && i + 1 < words.size()) return words[i + 1];  // OpEntryPoint
    i += length;
  }
  return 0;
}

TEST(MeshShaderSpirv, taskAndMeshShadersAreEmbeddedWithTheirStages) {
  const struct {
    const char* name;
    uint32_t model;
  } shaders[] = {{"fiblet_mesh.task", 5364}, {"fiblet_mesh.mesh", 5365}, {"fiblet_mesh_serial.mesh", 5365}};
  for (const auto& s : shaders) {
    SCOPED_TRACE(s.name);
    const std::span<const uint32_t> words = gpu::shaderWords(s.name);
    ASSERT_GT(words.size(), 5u);
    EXPECT_EQ(words[0], 0x07230203u);  // the SPIR-V magic
    EXPECT_EQ(entryPointModel(words), s.model);
  }
}

// The command line where the device lacks the extension (lavapipe): one
// line naming it, exit 2, no image; where it has it, a PNG.
class GpuCliMeshPipeline : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runCommand(std::string(FIBSCOPE_EXE) + " gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
    has_mesh_ = r.output.find("mesh shaders: enabled") != std::string::npos;
  }
  test::TempDir dir_;
  bool has_mesh_ = false;
};

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

TEST_F(GpuCliMeshPipeline, renderDrawsTheMeshPipelinesOrRefusesThemInOneLine) {
  for (const char* pipeline : {"mesh", "mesh-serial"}) {
    SCOPED_TRACE(pipeline);
    const std::string png = dir_.file(std::string(pipeline) + ".png");
    const auto r = test::runCommand(std::string(FIBSCOPE_EXE) +
                                    " render --validate --phantom-streamlines 60 --size 96x72 --view axial "
                                    "--pipeline " + pipeline + " -o " + png);
    if (has_mesh_) {
      ASSERT_EQ(r.exit_code, 0) << r.output;
      EXPECT_NE(r.output.find(std::string(pipeline) + " pipeline"), std::string::npos) << r.output;
      EXPECT_GT(test::readBytes(png).size(), 100u);
    } else {
      EXPECT_EQ(r.exit_code, 2) << r.output;
      EXPECT_EQ(lineCount(r.output), 1) << r.output;
      EXPECT_NE(r.output.find("VK_EXT_mesh_shader not supported by"), std::string::npos) << r.output;
      EXPECT_FALSE(std::filesystem::exists(png));
    }
  }
  if (!has_mesh_) {
    // bench refuses it the same way (a --compare list naming it).
    const auto bench = test::runCommand(std::string(FIBSCOPE_EXE) +
                                        " bench --phantom-streamlines 60 --size 64x48 --frames 2 "
                                        "--compare compute/frustum,mesh/frustum");
    EXPECT_EQ(bench.exit_code, 2) << bench.output;
    EXPECT_EQ(lineCount(bench.output), 1) << bench.output;
    EXPECT_NE(bench.output.find("VK_EXT_mesh_shader not supported by"), std::string::npos) << bench.output;
  }
}

}  // namespace
}  // namespace fibscope
