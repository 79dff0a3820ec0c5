// Adaptive detail of the viewer: which frames are drawn coarse, and what a
// coarse frame draws.
#include "app/viewer/adaptive_detail.h"

#include <gtest/gtest.h>

namespace fibscope {
namespace {

TEST(AdaptiveDetail, onlySlowMovingComputeFramesAreCoarse) {
  RenderSettings compute;
  EXPECT_TRUE(drawCoarse(true, compute, true, kSlowFrameMs + 1));
  EXPECT_FALSE(drawCoarse(false, compute, true, kSlowFrameMs + 1)) << "switched off";
  EXPECT_FALSE(drawCoarse(true, compute, false, 5000)) << "a still camera gets the full detail";
  EXPECT_FALSE(drawCoarse(true, compute, true, kSlowFrameMs)) << "fast enough frames stay full";
  EXPECT_FALSE(drawCoarse(true, compute, true, 0)) << "before any full frame was timed";
  RenderSettings lines;
  lines.pipeline = RenderPipeline::Lines;
  EXPECT_FALSE(drawCoarse(true, lines, true, 5000)) << "the baselines have no LoD";
}

TEST(AdaptiveDetail, coarseFramesUseTheLargerLodOneCullPassAndNoAmbientOcclusion) {
  RenderSettings s;
  s.culling = CullingMode::TwoPhase;
  s.lod_pixels = 4;
  s.ssao = true;
  s.line_width_px = 2.5f;
  s.color = ColorMode::Scalar;
  const RenderSettings c = coarseSettings(s, 160);
  EXPECT_EQ(c.lod_pixels, 160.0f);
  EXPECT_EQ(c.culling, CullingMode::Frustum);
  EXPECT_FALSE(c.ssao);
  // What the user chose otherwise is kept.
  EXPECT_EQ(c.line_width_px, 2.5f);
  EXPECT_EQ(c.color, ColorMode::Scalar);
  s.lod_pixels = 300;
  s.culling = CullingMode::None;
  EXPECT_EQ(coarseSettings(s, 160).lod_pixels, 300.0f) << "never finer than the user's own LoD";
  EXPECT_EQ(coarseSettings(s, 160).culling, CullingMode::Frustum) << "the LoD needs a cull pass";
}

TEST(AdaptiveDetail, sameViewComparesThePoseAndFieldOfViewNotTheSize) {
  Camera a;
  Camera b = a;
  b.width = a.width * 2;
  EXPECT_TRUE(sameView(a, b));
  b.eye[0] += 1e-9;
  EXPECT_FALSE(sameView(a, b));
  b = a;
  b.fov_y_deg += 1;
  EXPECT_FALSE(sameView(a, b));
  b = a;
  b.up = {0, 0, 1};
  EXPECT_FALSE(sameView(a, b));
}

TEST(AdaptiveDetail, slowHalfResolutionMovesDropToAQuarterAndComeBackWithoutAlternating) {
  EXPECT_EQ(coarseDivisor(2, 0), 2u) << "the first coarse frame: half resolution";
  EXPECT_EQ(coarseDivisor(2, kSlowFrameMs / 2), 2u);
  EXPECT_EQ(coarseDivisor(2, kSlowFrameMs + 1), 4u) << "still slow at half resolution";
  EXPECT_EQ(coarseDivisor(4, kSlowFrameMs + 1), 4u);
  EXPECT_EQ(coarseDivisor(4, kSlowFrameMs / 2), 4u)
      << "a quarter-resolution frame of half the limit would be about twice the limit at half resolution";
  EXPECT_EQ(coarseDivisor(4, kSlowFrameMs / 5), 2u) << "fast enough to go back";
  EXPECT_EQ(coarseDivisor(4, 0), 4u) << "no time measured: keep";
}

}  // namespace
}  // namespace fibscope
