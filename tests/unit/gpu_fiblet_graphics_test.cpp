// The paper's comparison pipelines (fibscope issue 18 item 4; section 4.5
// of the fiblets paper; src/render/gpu/fiblet_graphics_pass.h): the
// geometry and tessellation pipelines decode the same fiblets as the
// compute pipeline in a graphics stage and draw them with the device's
// line rasteriser. Checked against independent references:
//   - the CPU reference rasteriser of the raw polylines: >= 98 % of the
//     covered pixels of each image lie within 1 px of a covered pixel of
//     the other (the check); plain agreement and the largest
//     distance are printed and bounded as for the lines baseline, whose
//     rasteriser they share (the capsule rule is the compute rasters');
//   - the lines baseline from the same view: the same rasteriser on the
//     raw points, so coverage nearly the same;
//   - the compute pipeline: where both cover a pixel, the same fiber, and
//     where the fiber is the same, segment and tangent (the G-buffer
//     picking reads) mostly the same;
//   - each other (the same points to float rounding);
//   - a clip plane: the same cut as the lines baseline's;
//   - culling none against frustum and two-phase (the same coverage over
//     an orbit, a jump and a zoom; something culled), filtered fibers not
//     drawn, two models drawn with the scene's fiber numbering;
//   - the command line: a PNG from each, and one-line errors (exit 2).
// Validation layers on (GpuTest fails on any message). Skipped where the
// device lacks the stage (never on lavapipe).
//
// On lavapipe the tessellation pipeline draws in draws of at most 64
// patches (fiblet_graphics_pass.h: in larger ones the driver hands the
// tessellation stages other patches' inputs, which these tests caught).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/buffer.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "io/png_writer.h"
#include "render/camera.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/lines_pass.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/render_config.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::gbufferMask;
using test::renderPhantom;
using test::unpackTangent;

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

// Where both G-buffers cover a pixel: how often fiber, segment, tangent agree.
struct IdAgreement {
  size_t both = 0, same_fiber = 0, same_segment = 0, same_tangent = 0;
  size_t b_nearer = 0;  // different fiber, B's depth nearer
  size_t segment_a_after = 0, segment_b_after = 0;  // same fiber, A's segment index above B's / below
  size_t differentFiber() const { return both - same_fiber; }
};
IdAgreement compareIds(const std::vector<shader::GBufferTexel>& a, const std::vector<shader::GBufferTexel>& b) {
  IdAgreement r;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].fiber == shader::kNoFiberId || b[i].fiber == shader::kNoFiberId) continue;
    ++r.both;
    if (a[i].fiber != b[i].fiber) {
      r.b_nearer += b[i].depth < a[i].depth;
      continue;
    }
    ++r.same_fiber;
    r.segment_a_after += a[i].segment > b[i].segment;
    r.segment_b_after += a[i].segment < b[i].segment;
    if (a[i].segment != b[i].segment) continue;
    ++r.same_segment;
    const std::array<float, 3> s = unpackTangent(a[i].tangent), t = unpackTangent(b[i].tangent);
    r.same_tangent += s[0] * t[0] + s[1] * t[1] + s[2] * t[2] > 0.999f;
  }
  return r;
}

// Orientation shading of a G-buffer, for looking at the images.
void writeGBufferPng(const std::string& path, const std::vector<shader::GBufferTexel>& texels) {
  ReferenceFrame frame(kSize, kSize);
  for (size_t i = 0; i < texels.size(); ++i) {
    if (texels[i].fiber == shader::kNoFiberId) continue;
    frame.fiber[i] = texels[i].fiber;
    frame.tangent[i] = unpackTangent(texels[i].tangent);
  }
  writePngRgba(path, kSize, kSize, shadeOrientation(frame));
}

RenderSettings plainSettings(RenderPipeline pipeline, CullingMode culling, float width) {
  RenderSettings s;
  s.pipeline = pipeline;
  s.culling = culling;
  s.line_width_px = width;
  s.ssao = false;
  return s;
}

const RenderPipeline kBothPipelines[] = {RenderPipeline::Geometry, RenderPipeline::Tessellation};
std::string nameOf(RenderPipeline p) { return std::string(renderPipelineName(p)); }

struct View {
  const char* name;
  Camera camera;
};

class GpuFibletGraphics : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    const VkPhysicalDeviceFeatures& f = context().enabledFeatures();
    if (!context().info().queue_has_graphics || !f.geometryShader || !f.tessellationShader || !f.shaderClipDistance)
      GTEST_SKIP() << context().info().name << " lacks graphics, geometry or tessellation shaders or clip distances";
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

  static void maybeWritePng(const std::string& stem, const std::vector<shader::GBufferTexel>& texels) {
    if (const char* dir = std::getenv("FIBSCOPE_TEST_PNG_DIR")) writeGBufferPng(std::string(dir) + "/" + stem + ".png", texels);
  }

  Tractogram fibers_;
  Bounds bounds_;
  std::unique_ptr<TractogramUpload> upload_;
  std::vector<View> views_;

  // The checks of each pipeline (the tests below call them).
  void coversTheCpuReference(RenderPipeline pipeline);
  void agreesWithTheComputePipeline(RenderPipeline pipeline);
};

void GpuFibletGraphics::coversTheCpuReference(RenderPipeline pipeline) {
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
  FrameRenderer renderer(context(), kSize, kSize);
  for (float requested : {1.0f, 3.0f}) {
    const float width = linesDrawnWidth(context(), requested);  // 1 without wideLines
    if (requested > 1.0f && width == 1.0f) continue;
    for (const View& view : views_) {
      const ReferenceFrame reference = rasterizeReference(fibers_, view.camera, width);
      const std::vector<uint8_t> reference_mask = reference.coverageMask();
      const auto lines = render(renderer, view.camera, plainSettings(RenderPipeline::Lines, CullingMode::None, requested),
                                GpuScene{nullptr, &raw});
      const CoverageComparison lines_c = compareCoverage(gbufferMask(lines), reference_mask, kSize, kSize);
      {
        SCOPED_TRACE(nameOf(pipeline) + " " + view.name + ", width " + std::to_string(width));
        FrameStats stats;
        const auto texels =
            render(renderer, view.camera, plainSettings(pipeline, CullingMode::None, requested), GpuScene{&dataset()}, &stats);
        maybeWritePng(nameOf(pipeline) + "-" + view.name + "-w" + std::to_string(int(width)), texels);
        const std::vector<uint8_t> mask = gbufferMask(texels);
        const CoverageComparison c = compareCoverage(mask, reference_mask, kSize, kSize);
        ASSERT_GT(c.covered_b, kSize * kSize / 20) << "the view shows the phantom: " << c.summary();
        const double within = fractionWithin(mask, reference_mask, 1.0);
        const CoverageComparison vs_lines = compareCoverage(mask, gbufferMask(lines), kSize, kSize);
        std::printf("[ GPU      ] %s %s w%.0f: vs reference %s, within 1 px %.4f; lines baseline agreement %.4f; "
                    "vs lines %.4f; %.2f ms\n",
                    nameOf(pipeline).c_str(), view.name, width, c.summary().c_str(), within, lines_c.agreement,
                    vs_lines.agreement, stats.gpu_ms);
        EXPECT_EQ(stats.fiblets_drawn, stats.fiblets_total);
        // The check: >= 98 % of the covered pixels within 1 px.
        EXPECT_GE(within, 0.98) << c.summary();
        // Pixel for pixel the device's lines differ from the capsule rule
        // as the lines baseline's do (lines_pass.h; gpu_baselines_test):
        // its bounds, and no worse than the baseline by more than a little.
        // Measured on lavapipe: up to 2.83 px (2 sqrt 2) reference -> line,
        // where the lines baseline at 200 px measures up to 2.24.
        EXPECT_LE(c.max_distance_a_to_b, 1.5) << c.summary();
        EXPECT_LE(c.max_distance_b_to_a, 3.0) << c.summary();
        EXPECT_GE(c.agreement, lines_c.agreement - 0.02) << c.summary() << " (lines: " << lines_c.summary() << ")";
        EXPECT_GE(vs_lines.agreement, 0.9) << vs_lines.summary();
      }
    }
  }
}

void GpuFibletGraphics::agreesWithTheComputePipeline(RenderPipeline pipeline) {
  FrameRenderer renderer(context(), kSize, kSize);
  std::vector<View> views = views_;
  // Close enough that a segment spans pixels: there the winning segment,
  // not only the fiber, is comparable.
  views.push_back({"very-close", orbitCamera(bounds_, 37, 23, kSize, kSize, 0.04)});
  for (const View& view : views) {
    SCOPED_TRACE(nameOf(pipeline) + " " + view.name);
    const auto compute =
        render(renderer, view.camera, plainSettings(RenderPipeline::Compute, CullingMode::None, 1.0f), GpuScene{&dataset()});
    maybeWritePng(std::string("compute-") + view.name + "-w1", compute);
    const auto drawn = render(renderer, view.camera, plainSettings(pipeline, CullingMode::None, 1.0f), GpuScene{&dataset()});
    const IdAgreement ids = compareIds(drawn, compute);
    std::printf("[ GPU      ] %s %s vs compute: of %zu both, same fiber %zu (segment %zu, tangent %zu), other fiber "
                "%zu (%zu nearer in compute); segment above compute's %zu, below %zu\n",
                nameOf(pipeline).c_str(), view.name, ids.both, ids.same_fiber, ids.same_segment, ids.same_tangent,
                ids.differentFiber(), ids.b_nearer, ids.segment_a_after, ids.segment_b_after);
    ASSERT_GT(ids.both, 200u);
    // The compute rasters' capsules cover a pixel from every segment within
    // the radius, the nearest winning; a line only from the segments whose
    // rectangle holds the centre. So where fibers overlap the winner can
    // differ, and then compute's is the nearer one (not a depth-order
    // error): the lines baseline against the reference measures the same
    // (gpu_baselines_test). Measured here 0.88-0.96 at whole-brain views.
    EXPECT_GE(double(ids.same_fiber), 0.85 * double(ids.both));
    if (ids.differentFiber() >= 100) EXPECT_GE(double(ids.b_nearer), 0.9 * double(ids.differentFiber()));
    if (std::string(view.name) == "very-close") {
      // Segment ids are the point index within the fiblet (picking reads
      // them): close up, the same one wins often (measured 0.30 of the same
      // fiber's pixels; the others split evenly above and below, so no
      // offset in the numbering), and its tangent is the same.
      EXPECT_GE(double(ids.same_segment), 0.2 * double(ids.same_fiber));
      EXPECT_GE(double(ids.same_tangent), 0.98 * double(ids.same_segment));
    }
  }
}

TEST_F(GpuFibletGraphics, geometryCoversTheCpuReferenceAsTheLinesBaselineDoes) {
  coversTheCpuReference(RenderPipeline::Geometry);
}

TEST_F(GpuFibletGraphics, geometryIdsAgreeWithTheComputePipeline) { agreesWithTheComputePipeline(RenderPipeline::Geometry); }

TEST_F(GpuFibletGraphics, tessellationCoversTheCpuReferenceAsTheLinesBaselineDoes) {
  coversTheCpuReference(RenderPipeline::Tessellation);
}

TEST_F(GpuFibletGraphics, tessellationIdsAgreeWithTheComputePipeline) {
  agreesWithTheComputePipeline(RenderPipeline::Tessellation);
}

TEST_F(GpuFibletGraphics, frustumAndTwoPhaseCullingKeepTheCoverageOfDrawingEveryFiblet) {
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  // An orbit of a few frames (two-phase learns from the last), a jump and a
  // zoom in (the frustum culls part of the phantom).
  const View views[] = {{"orbit 0", orbitCamera(bounds_, 30, 20, kSize, kSize, 1.0)},
                        {"orbit 1", orbitCamera(bounds_, 31.14, 20, kSize, kSize, 1.0)},
                        {"orbit 2", orbitCamera(bounds_, 32.28, 20, kSize, kSize, 1.0)},
                        {"jump", orbitCamera(bounds_, 92.28, 20, kSize, kSize, 1.0)},
                        {"zoomed", orbitCamera(bounds_, 93.42, 20, kSize, kSize, 0.25)}};
  constexpr size_t kViews = std::size(views);
  for (const RenderPipeline pipeline : kBothPipelines) {
  // The unculled frames are the same for both culling modes: drawn once.
  std::vector<shader::GBufferTexel> nones[kViews];
  for (size_t v = 0; v < kViews; ++v) {
    FrameStats none_stats;
    nones[v] = render(reference, views[v].camera, plainSettings(pipeline, CullingMode::None, 2.0f),
                      GpuScene{&dataset()}, &none_stats);
    EXPECT_EQ(none_stats.fiblets_drawn, none_stats.fiblets_total)
        << renderPipelineName(pipeline) << " " << views[v].name;
  }
  for (CullingMode mode : {CullingMode::Frustum, CullingMode::TwoPhase}) {
    bool culled_some = false;
    for (size_t v = 0; v < kViews; ++v) {
      const View& view = views[v];
      SCOPED_TRACE(std::string(renderPipelineName(pipeline)) + " " + std::string(cullingModeName(mode)) + " " +
                   view.name);
      FrameStats stats;
      const std::vector<shader::GBufferTexel>& none = nones[v];
      const auto drawn =
          render(culled, view.camera, plainSettings(pipeline, mode, 2.0f), GpuScene{&dataset()}, &stats);
      const CoverageComparison c = compareCoverage(gbufferMask(none), gbufferMask(drawn), kSize, kSize);
      size_t fiber_diff = 0;
      for (size_t i = 0; i < none.size(); ++i)
        fiber_diff += none[i].fiber != shader::kNoFiberId && drawn[i].fiber != shader::kNoFiberId &&
                      none[i].fiber != drawn[i].fiber;
      std::printf("[ GPU      ] %s %s %s: %s; other fiber %zu; drawn %llu of %llu\n",
                  renderPipelineName(pipeline).data(), cullingModeName(mode).data(), view.name, c.summary().c_str(), fiber_diff, (unsigned long long)stats.fiblets_drawn,
                  (unsigned long long)stats.fiblets_total);
      ASSERT_GT(c.covered_a, 0u);
      // Culling is conservative: the same pixels. (Fibers may differ only
      // at depth ties, the draw order being the lists'.)
      EXPECT_EQ(c.covered_a, c.covered_b) << c.summary();
      EXPECT_EQ(c.covered_both, c.covered_a) << c.summary();
      EXPECT_LE(fiber_diff, c.covered_a / 100);
      EXPECT_EQ(stats.fiblets_lod, 0u);  // no LoD in these pipelines
      culled_some |= stats.fiblets_drawn < stats.fiblets_total;
    }
    EXPECT_TRUE(culled_some) << "something is culled";
  }
  }
}

TEST_F(GpuFibletGraphics, filteredFibersAreNotDrawnAndTwoModelsKeepTheSceneNumbering) {
  FrameRenderer renderer(context(), kSize, kSize);
  const Camera& camera = views_[1].camera;
  // Even fibers kept.
  const uint32_t fibers = dataset().block().fiber_count;
  std::vector<uint32_t> words((fibers + 31) / 32, 0x55555555u);
  gpu::Buffer& kept = buffer(words.size() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
  gpu::uploadToBuffer(context(), kept, words.data(), words.size() * sizeof(uint32_t));
  // A second model: another phantom, numbered after the first's fibers.
  const Tractogram other_fibers = renderPhantom(200, 9);
  const TractogramUpload other = uploadTractogram(context(), other_fibers, "other");
  for (RenderPipeline pipeline : kBothPipelines) {
    SCOPED_TRACE(nameOf(pipeline));
    for (CullingMode culling : {CullingMode::None, CullingMode::Frustum}) {
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
    // Two models against the compute pipeline's numbering.
    GpuScene two;
    two.datasets = {&dataset(), &other.dataset};
    const auto compute = render(renderer, camera, plainSettings(RenderPipeline::Compute, CullingMode::None, 1.0f), two);
    const auto drawn = render(renderer, camera, plainSettings(pipeline, CullingMode::Frustum, 1.0f), two);
    size_t second = 0;
    for (const shader::GBufferTexel& t : drawn) second += t.fiber != shader::kNoFiberId && t.fiber >= fibers;
    const IdAgreement ids = compareIds(drawn, compute);
    EXPECT_GT(second, 100u) << "the second model is drawn";
    // (As in agreesWithTheComputePipeline.)
    EXPECT_GE(double(ids.same_fiber), 0.85 * double(ids.both));
    EXPECT_GE(double(ids.b_nearer), 0.9 * double(ids.differentFiber()));
  }
}

TEST_F(GpuFibletGraphics, clipPlanesCutTheGeometryPipelineAsTheComputeOne) {
  FrameRenderer renderer(context(), kSize, kSize);
  const Camera& camera = views_[3].camera;
  const double cx = 0.5 * (bounds_.min[0] + bounds_.max[0]);
  for (CullingMode culling : {CullingMode::None, CullingMode::Frustum}) {
    SCOPED_TRACE(cullingModeName(culling));
    RenderSettings compute = plainSettings(RenderPipeline::Compute, culling, 1.0f);
    compute.clip_planes = {{1.0, 0.0, 0.0, -cx}};  // keeps x >= the centre: the right half
    compute.lod_pixels = 0;
    RenderSettings geometry = compute;
    geometry.pipeline = RenderPipeline::Geometry;
    const auto whole = render(renderer, camera, plainSettings(RenderPipeline::Geometry, culling, 1.0f), GpuScene{&dataset()});
    const auto a = render(renderer, camera, geometry, GpuScene{&dataset()});
    const auto b = render(renderer, camera, compute, GpuScene{&dataset()});
    const CoverageComparison cut = compareCoverage(gbufferMask(a), gbufferMask(whole), kSize, kSize);
    const CoverageComparison c = compareCoverage(gbufferMask(a), gbufferMask(b), kSize, kSize);
    const auto compute_whole =
        render(renderer, camera, plainSettings(RenderPipeline::Compute, culling, 1.0f), GpuScene{&dataset()});
    const CoverageComparison unclipped = compareCoverage(gbufferMask(whole), gbufferMask(compute_whole), kSize, kSize);
    const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
    RenderSettings lines_settings = compute;
    lines_settings.pipeline = RenderPipeline::Lines;
    const auto lines = render(renderer, camera, lines_settings, GpuScene{nullptr, &raw});
    const CoverageComparison vs_lines = compareCoverage(gbufferMask(a), gbufferMask(lines), kSize, kSize);
    const CoverageComparison lines_compute = compareCoverage(gbufferMask(lines), gbufferMask(b), kSize, kSize);
    std::printf("[ GPU      ] geometry clipped vs compute clipped: %s; of the whole %.2f; unclipped: %s; vs lines clipped %s; lines vs compute %s\n",
                c.summary().c_str(), double(cut.covered_a) / double(cut.covered_b), unclipped.summary().c_str(),
                vs_lines.summary().c_str(), lines_compute.summary().c_str());
    EXPECT_LT(cut.covered_a, cut.covered_b * 3 / 4) << "the plane cuts about half away";
    EXPECT_GT(cut.covered_a, cut.covered_b / 4);
    // The lines baseline clips the same way (gl_ClipDistance): the same
    // cut to the rasterisers' pixel.
    EXPECT_LE(vs_lines.maxDistance(), 1.5) << vs_lines.summary();
    EXPECT_GE(vs_lines.agreement, 0.97) << vs_lines.summary();
    // Against the compute rasters' clip (clip-space segments): >= 98 % of
    // the pixels within 1 px. (Both line pipelines measure a few compute
    // pixels up to 10 px from any of theirs at this plane: a difference
    // between the two clipping paths older than these pipelines.)
    EXPECT_GE(fractionWithin(gbufferMask(a), gbufferMask(b), 1.0), 0.98) << c.summary();
  }
}

// The command line, as a user meets it.
class GpuCliFibletGraphics : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = test::runCommand(std::string(FIBSCOPE_EXE) + " gpu-info");
    if (r.exit_code != 0) GTEST_SKIP() << "no usable Vulkan device: " << r.output;
  }
  test::TempDir dir_;
};

int lineCount(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

TEST_F(GpuCliFibletGraphics, renderDrawsEachPipelineToAPngAndRefusesBadNamesInOneLine) {
  for (const char* pipeline : {"geometry", "tessellation"}) {
    SCOPED_TRACE(pipeline);
    const std::string png = dir_.file(std::string(pipeline) + ".png");
    // (Small: the tessellation pipeline is slow on lavapipe.)
    const auto r = test::runCommand(std::string(FIBSCOPE_EXE) +
                                    " render --validate --phantom-streamlines 60 --size 96x72 --view axial "
                                    "--pipeline " + pipeline + " -o " + png);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(std::string(pipeline) + " pipeline"), std::string::npos) << r.output;
    EXPECT_GT(test::readBytes(png).size(), 100u);
  }
  const auto bad = test::runCommand(std::string(FIBSCOPE_EXE) +
                                    " render --phantom-streamlines 100 --size 64x48 --pipeline geometri -o " +
                                    dir_.file("bad.png"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_EQ(lineCount(bad.output), 1) << bad.output;
  EXPECT_NE(bad.output.find("tessellation"), std::string::npos) << "the accepted names: " << bad.output;
  // Coverage culling re-projects the compute pipeline's keys: refused here.
  const auto coverage = test::runCommand(std::string(FIBSCOPE_EXE) +
                                         " render --phantom-streamlines 100 --size 64x48 --pipeline geometry "
                                         "--culling coverage -o " + dir_.file("coverage.png"));
  EXPECT_EQ(coverage.exit_code, 2) << coverage.output;
  EXPECT_EQ(lineCount(coverage.output), 1) << coverage.output;
  EXPECT_FALSE(std::filesystem::exists(dir_.file("coverage.png")));
}

}  // namespace
}  // namespace fibscope
