// Several models drawn in one frame (render/gpu/scene_table.h): the union of
// two overlapping phantoms against the CPU reference of their raw union,
// two-phase culling across models, hiding a model, picking and the
// selection highlight with scene-global fiber ids. lavapipe with validation
// on (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/fiber_attributes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/pick.h"
#include "render/gpu/scene_table.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

using test::gbufferMask;
using test::renderPhantom;

constexpr uint32_t kSize = 160;

RenderSettings plainSettings(CullingMode culling, float line_width) {
  RenderSettings settings;
  settings.culling = culling;
  settings.lod_pixels = 0;  // LoD changes the image by design: the comparisons want every segment
  settings.line_width_px = line_width;
  settings.ssao = false;
  settings.fxaa = false;
  return settings;
}

// Moves every point by (dx, dy, dz) mm.
Tractogram shifted(Tractogram t, float dx, float dy, float dz) {
  for (size_t i = 0; i < t.positions.size(); i += 3) {
    t.positions[i] += dx;
    t.positions[i + 1] += dy;
    t.positions[i + 2] += dz;
  }
  return t;
}

// A's streamlines, then B's: fiber u of the union is A's u below A's count,
// else B's u - A's count, as the scene numbers them.
Tractogram unionOf(const Tractogram& a, const Tractogram& b) {
  Tractogram u;
  for (const Tractogram* t : {&a, &b})
    for (size_t s = 0; s < t->streamlineCount(); ++s) u.addStreamline(t->point(t->offsets[s]), t->pointsIn(s));
  return u;
}

class GpuMultiModel : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    // Two different phantoms overlapping in space (B a few mm off A), so
    // fibers of both compete for the same pixels.
    fibers_a_ = renderPhantom(300, 5);
    fibers_b_ = shifted(renderPhantom(300, 9), 6.0f, -3.0f, 4.0f);
    union_ = unionOf(fibers_a_, fibers_b_);
    bounds_ = tractogramBounds(union_);
    a_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers_a_, "a"));
    b_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers_b_, "b"));
  }
  void TearDown() override {
    a_.reset();
    b_.reset();
    test::GpuTest::TearDown();
  }

  const GpuDataset& a() const { return a_->dataset; }
  const GpuDataset& b() const { return b_->dataset; }
  GpuScene both() const {
    GpuScene scene;
    scene.datasets = {&a(), &b()};
    return scene;
  }
  uint32_t fibersA() const { return uint32_t(fibers_a_.streamlineCount()); }

  Tractogram fibers_a_, fibers_b_, union_;
  Bounds bounds_;
  std::unique_ptr<TractogramUpload> a_, b_;
};

TEST_F(GpuMultiModel, twoModelsDrawnTogetherMatchTheReferenceOfTheirUnion) {
  FrameRenderer together(context(), kSize, kSize), alone(context(), kSize, kSize);
  const RenderSettings settings = plainSettings(CullingMode::None, 2.0f);
  const Camera views[] = {standardView(bounds_, StandardView::Sagittal, kSize, kSize),
                          orbitCamera(bounds_, 37, 23, kSize, kSize, 0.6)};
  for (const Camera& camera : views) {
    const FrameStats stats = together.render(camera, settings, both());
    EXPECT_EQ(stats.fiblets_total, uint64_t(a().block().fiblet_count) + b().block().fiblet_count);
    const auto texels = downloadGBuffer(context(), together.targets());
    const ReferenceFrame reference = rasterizeReference(union_, camera, 2.0f);
    const CoverageComparison c = compareCoverage(gbufferMask(texels), reference.coverageMask(), kSize, kSize);
    std::printf("two models: %s\n", c.summary().c_str());
    ASSERT_GT(c.covered_b, kSize * kSize / 20) << "the view shows the phantoms: " << c.summary();
    EXPECT_GE(c.agreement, 0.98) << c.summary();
    EXPECT_LE(c.maxDistance(), 1.0) << c.summary();

    // The winning (model, fiber) is the reference's union fiber.
    alone.render(camera, settings, GpuScene{&a()});
    const auto only_a = downloadGBuffer(context(), alone.targets());
    size_t both_cover = 0, same = 0, b_wins = 0, b_over_a = 0, same_tangent = 0;
    for (size_t i = 0; i < texels.size(); ++i) {
      if (texels[i].fiber == shader::kNoFiberId) continue;
      const bool from_b = texels[i].fiber >= fibersA();
      b_wins += from_b;
      // B in front of a fiber A draws at that pixel: depth compositing.
      b_over_a += from_b && only_a[i].fiber != shader::kNoFiberId;
      if (reference.fiber[i] == kNoFiber) continue;
      ++both_cover;
      if (texels[i].fiber != reference.fiber[i]) continue;
      ++same;
      // The tangent cache is indexed by the global fiblet: B's tangents are
      // its own, not those of A's fiblet with the same index.
      const std::array<float, 3> t = test::unpackTangent(texels[i].tangent), r = reference.tangent[i];
      same_tangent += std::fabs(t[0] * r[0] + t[1] * r[1] + t[2] * r[2]) > 0.9f;
    }
    EXPECT_GE(double(same), 0.95 * double(both_cover)) << same << " of " << both_cover;
    EXPECT_GE(double(same_tangent), 0.95 * double(same)) << same_tangent << " of " << same;
    EXPECT_GT(b_wins, texels.size() / 50) << "model B is drawn";
    EXPECT_GT(b_over_a, 100u) << "B's fibers win pixels A also covers";
    EXPECT_LT(b_wins, c.covered_a - texels.size() / 50) << "model A is drawn too";
  }
}

TEST_F(GpuMultiModel, twoPhaseCullingAcrossModelsKeepsEveryVisiblePixel) {
  std::vector<Camera> orbit;
  for (int i = 0; i < 5; ++i) orbit.push_back(orbitCamera(bounds_, 30 + 1.14 * i, 20, kSize, kSize, 1.0));
  orbit.push_back(orbitCamera(bounds_, 30 + 1.14 * 4 + 60, 20, kSize, kSize, 1.0));  // a 60 degree jump
  orbit.push_back(orbitCamera(bounds_, 30 + 1.14 * 5 + 60, 20, kSize, kSize, 1.0));
  orbit.push_back(orbitCamera(bounds_, 30 + 1.14 * 5 + 60, 20, kSize, kSize, 0.5));  // zoom in
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  const RenderSettings none = plainSettings(CullingMode::None, 2.5f);
  const RenderSettings two_phase = plainSettings(CullingMode::TwoPhase, 2.5f);
  uint64_t fewest_drawn = UINT64_MAX, total = 0;
  for (size_t f = 0; f < orbit.size(); ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    reference.render(orbit[f], none, both());
    const FrameStats stats = culled.render(orbit[f], two_phase, both());
    const auto x = downloadGBuffer(context(), reference.targets());
    const auto y = downloadGBuffer(context(), culled.targets());
    const auto keys_x = downloadVisibility(context(), reference.targets());
    const auto keys_y = downloadVisibility(context(), culled.targets());
    size_t covered = 0, coverage_diff = 0, fiber_diff = 0, key_diff = 0, from_b = 0;
    for (size_t i = 0; i < x.size(); ++i) {
      const bool cx = x[i].fiber != shader::kNoFiberId, cy = y[i].fiber != shader::kNoFiberId;
      covered += cx;
      coverage_diff += cx != cy;
      fiber_diff += cx && cy && x[i].fiber != y[i].fiber;
      key_diff += keys_x[i] != keys_y[i];
      from_b += cx && x[i].fiber >= fibersA();
    }
    ASSERT_GT(covered, kSize * kSize / 20u) << "the view shows the phantoms";
    ASSERT_GT(from_b, covered / 10) << "both models are in view";
    EXPECT_EQ(coverage_diff, 0u) << "of " << covered << " covered pixels";
    EXPECT_EQ(fiber_diff, 0u);
    EXPECT_EQ(key_diff, 0u) << "the visibility buffers differ";
    total = stats.fiblets_total;
    if (f > 0) fewest_drawn = std::min(fewest_drawn, stats.fiblets_drawn);
  }
  std::printf("two-phase over two models: at least %llu of %llu fiblets drawn\n",
              static_cast<unsigned long long>(fewest_drawn), static_cast<unsigned long long>(total));
  EXPECT_LT(fewest_drawn, total) << "occlusion culls fiblets of the two models";
}

TEST_F(GpuMultiModel, hidingAModelDrawsExactlyTheOtherModel) {
  // One renderer draws both, then B alone (A hidden), with two-phase
  // culling (its history, lists and tangent cache were made for two
  // models), and then A alone; each frame equals a fresh renderer's frame
  // of that model alone, bit for bit.
  const Camera camera = orbitCamera(bounds_, 50, 15, kSize, kSize, 0.8);
  const RenderSettings settings = plainSettings(CullingMode::TwoPhase, 2.0f);
  FrameRenderer shared(context(), kSize, kSize);
  shared.render(camera, settings, both());
  shared.render(camera, settings, both());
  const auto with_both = downloadGBuffer(context(), shared.targets());
  for (const GpuDataset* shown : {&b(), &a()}) {
    SCOPED_TRACE(shown == &a() ? "A alone" : "B alone");
    shared.render(camera, settings, GpuScene{shown});
    const auto hidden = downloadGBuffer(context(), shared.targets());
    FrameRenderer fresh(context(), kSize, kSize);
    fresh.render(camera, settings, GpuScene{shown});
    const auto alone = downloadGBuffer(context(), fresh.targets());
    ASSERT_EQ(hidden.size(), alone.size());
    size_t covered = 0, differ = 0, offset_mismatch = 0;
    const uint32_t base = shown == &b() ? fibersA() : 0;
    for (size_t i = 0; i < alone.size(); ++i) {
      covered += alone[i].fiber != shader::kNoFiberId;
      differ += hidden[i].fiber != alone[i].fiber || hidden[i].segment != alone[i].segment ||
                hidden[i].depth != alone[i].depth || hidden[i].tangent != alone[i].tangent;
      // Where the shown model won with both drawn, it wins alone with the
      // same fiber less its scene offset, at the same depth.
      const uint32_t g = with_both[i].fiber;
      const bool its = g != shader::kNoFiberId && g >= base && g - base < shown->block().fiber_count;
      if (its) offset_mismatch += alone[i].fiber != g - base || alone[i].depth != with_both[i].depth;
    }
    ASSERT_GT(covered, kSize * kSize / 20u);
    EXPECT_EQ(differ, 0u) << "of " << covered << " covered pixels";
    EXPECT_EQ(offset_mismatch, 0u);
  }
}

TEST_F(GpuMultiModel, pickingModelBNamesModelBAndTheSelectionHighlightsOnlyItsFiber) {
  const Camera camera = orbitCamera(bounds_, 37, 23, kSize, kSize, 0.6);
  RenderSettings settings = plainSettings(CullingMode::TwoPhase, 2.0f);
  settings.color = ColorMode::Solid;
  settings.lighting = Lighting::None;
  settings.solid_color = {1.0f, 1.0f, 1.0f};
  settings.background = {0.0f, 0.0f, 0.0f};
  settings.highlight_color = {1.0f, 0.0f, 0.0f};
  settings.dim_unselected = 1.0f;  // unselected fibers fade into the background
  FrameRenderer renderer(context(), kSize, kSize);
  renderer.render(camera, settings, both());
  const auto texels = downloadGBuffer(context(), renderer.targets());
  const SceneLayout& layout = renderer.sceneLayout();
  ASSERT_EQ(layout.entries.size(), 2u);
  EXPECT_EQ(layout.entries[1].fiber_base, fibersA());
  EXPECT_EQ(layout.fibers, fibersA() + fibers_b_.streamlineCount());

  // A pixel where B wins and the CPU reference of the union agrees.
  const ReferenceFrame reference = rasterizeReference(union_, camera, 2.0f);
  size_t pixel = texels.size();
  for (size_t i = 0; i < texels.size() && pixel == texels.size(); ++i)
    if (texels[i].fiber != shader::kNoFiberId && texels[i].fiber >= fibersA() && reference.fiber[i] == texels[i].fiber)
      pixel = i;
  ASSERT_LT(pixel, texels.size()) << "no pixel of model B";
  const PickResult pick = pickFiber(context(), renderer.targets(), uint32_t(pixel % kSize), uint32_t(pixel / kSize));
  ASSERT_TRUE(pick.hit);
  const std::optional<SceneFiber> where = locateSceneFiber(layout, pick.fiber);
  ASSERT_TRUE(where);
  EXPECT_EQ(where->dataset, 1u) << "model B";
  EXPECT_EQ(where->fiber, reference.fiber[pixel] - fibersA()) << "B's own fiber index";
  EXPECT_FALSE(locateSceneFiber(layout, layout.fibers));

  // Select B's fiber: only its pixels are highlighted, including none of
  // A's fiber with the same index.
  const uint32_t selected = pick.fiber;
  GpuFiberAttributes attributes(context(), layout.fibers);
  std::vector<uint32_t> words(selectionWordCount(layout.fibers), 0);
  words[selected / 32] |= 1u << (selected % 32);
  attributes.uploadSelection(words);
  GpuScene scene = both();
  scene.selection_bits = attributes.selection();
  renderer.render(camera, settings, scene);
  const auto rgba = downloadColor(context(), renderer.targets());
  const auto after = downloadGBuffer(context(), renderer.targets());
  size_t highlighted = 0, wrong = 0, same_index_in_a = 0;
  for (size_t i = 0; i < after.size(); ++i) {
    const bool red = rgba[4 * i] > 200 && rgba[4 * i + 1] < 50 && rgba[4 * i + 2] < 50;
    const bool lit = rgba[4 * i] > 10 || rgba[4 * i + 1] > 10 || rgba[4 * i + 2] > 10;
    if (after[i].fiber == selected) {
      highlighted += red;
      wrong += !red;
    } else {
      wrong += lit;  // dimmed to the black background
      same_index_in_a += after[i].fiber == selected - fibersA();
    }
  }
  std::printf("selected fiber %u (B's %u): %zu pixels highlighted, %zu pixels of A's fiber %u dimmed\n", selected,
              where->fiber, highlighted, same_index_in_a, where->fiber);
  EXPECT_GT(highlighted, 0u);
  EXPECT_EQ(wrong, 0u);
}

TEST_F(GpuMultiModel, scenesBeyondTheTableOrTheKeyAreErrors) {
  std::vector<const GpuDataset*> many(shader::kMaxSceneDatasets + 1, &a());
  EXPECT_THROW(sceneLayout(many), Error);
  many.resize(shader::kMaxSceneDatasets);
  const SceneLayout layout = sceneLayout(many);
  EXPECT_EQ(layout.entries.back().fiblet_base, (shader::kMaxSceneDatasets - 1) * a().block().fiblet_count);
  // A frame with no dataset and the compute pipeline is refused.
  FrameRenderer renderer(context(), 32, 32);
  const Camera camera = orbitCamera(bounds_, 0, 0, 32, 32, 1.0);
  EXPECT_THROW(renderer.render(camera, plainSettings(CullingMode::None, 1.0f), GpuScene{}), Error);
}

}  // namespace
}  // namespace fibscope
