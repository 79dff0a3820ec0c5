// Fiber bundling on the GPU (bundling/gpu/gpu_bundler.h) against the
// double-precision CPU reference (bundling/bundle_reference.h), stage by
// stage on the GPU's own inputs (so each stage is checked alone), for a
// whole iteration and for the finishing relaxation and mapping back; runs
// are bit-identical and keep the model's fibers and offsets. A small model
// on a grid of about 30 voxels a side (lavapipe). Validation layers on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bundling/bundle_params.h"
#include "bundling/bundle_reference.h"
#include "bundling/bundle_setup.h"
#include "bundling/gpu/gpu_bundler.h"
#include "core/error.h"
#include "bundling_test_model.h"
#include "gpu_test_context.h"

namespace fibscope {
namespace {

class GpuBundling : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    model_ = test::wavyBundlingModel(240);
    params_.voxel_mm = 3;
    params_.step_mm = 2.5;
    params_.radius = 3.5;
    params_.iterations = 4;
    setup_ = planBundling(model_, params_);
  }

  Tractogram model_;
  BundleParams params_;
  BundleSetup setup_;
};

BundleSamples toDouble(const std::vector<glm::vec4>& v) {
  BundleSamples out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = glm::dvec3(v[i]);
  return out;
}

double maxDistance(const BundleSamples& a, const std::vector<glm::vec4>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i) m = std::max(m, glm::length(a[i] - glm::dvec3(b[i])));
  return m;
}

// Mean distance of the GPU's samples from the reference's, and the
// reference's mean motion from where the samples started (mm).
struct Agreement {
  double error = 0, motion = 0;
};
Agreement agreement(const BundleSamples& expect, const BundleSamples& original, const std::vector<glm::vec4>& gpu) {
  Agreement a;
  for (size_t i = 0; i < expect.size(); ++i) {
    a.error += glm::length(expect[i] - glm::dvec3(gpu[i])) / double(expect.size());
    a.motion += glm::length(expect[i] - original[i]) / double(expect.size());
  }
  return a;
}

}  // namespace

TEST_F(GpuBundling, resamplingMatchesTheReference) {
  GpuBundler bundler(context());
  bundler.load(model_, setup_, params_);
  const std::vector<glm::vec4> gpu = bundler.originalSamples();
  const BundleSamples cpu = resampleReference(model_, setup_);
  ASSERT_EQ(gpu.size(), cpu.size());
  ASSERT_GT(cpu.size(), 2000u);
  EXPECT_LT(maxDistance(cpu, gpu), 1e-4);
  EXPECT_EQ(toDouble(bundler.samples()), toDouble(gpu));
}

TEST_F(GpuBundling, eachStageOfAnIterationMatchesTheReference) {
  GpuBundler bundler(context(), GpuBundlerOptions{.keep_stages = true});
  bundler.load(model_, setup_, params_);
  const BundleSamples before = toDouble(bundler.samples());
  const double radius = params_.radius;
  bundler.iterate(radius);
  const BundleGrid& grid = setup_.grid;

  // Counts: exact.
  const std::vector<double> counts = countReference(before, grid);
  const std::vector<uint32_t> gpu_counts = bundler.counts();
  ASSERT_EQ(gpu_counts.size(), counts.size());
  double total = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    ASSERT_EQ(double(gpu_counts[i]), counts[i]) << i;
    total += counts[i];
  }
  EXPECT_EQ(total, double(before.size()));

  // Density: the three float passes equal the direct 3-D product-kernel
  // convolution to float rounding.
  const std::vector<double> direct = densityDirectReference(counts, grid, radius);
  const std::vector<float> density = bundler.density();
  double scale = 0;
  for (double d : direct) scale = std::max(scale, d);
  ASSERT_GT(scale, 5);
  for (size_t i = 0; i < direct.size(); ++i) ASSERT_NEAR(density[i], direct[i], 2e-6 * scale) << i;

  // Gradient of the GPU's density.
  const std::vector<double> density_d(density.begin(), density.end());
  const std::vector<glm::dvec3> grad = gradientReference(density_d, grid);
  const std::vector<glm::vec4> gpu_grad = bundler.gradient();
  double gscale = 0;
  for (const glm::dvec3& g : grad) gscale = std::max(gscale, glm::length(g));
  for (size_t i = 0; i < grad.size(); ++i) {
    ASSERT_NEAR(glm::length(grad[i] - glm::dvec3(gpu_grad[i])), 0, 1e-6 * gscale) << i;
    ASSERT_EQ(gpu_grad[i].w, 0.0f);
  }

  // Advection on the GPU's gradient: the reference's moves, orthogonal to
  // the fiber and of length at most R h.
  std::vector<glm::dvec3> gpu_grad_d(gpu_grad.size());
  for (size_t i = 0; i < gpu_grad.size(); ++i) gpu_grad_d[i] = glm::dvec3(gpu_grad[i]);
  const double step = bundleAdvectionStep(params_, setup_, radius);
  const BundleSamples advected = advectReference(before, setup_.sample_offsets, gpu_grad_d, grid, step, false);
  const std::vector<glm::vec4> gpu_advected = bundler.advected();
  EXPECT_LT(maxDistance(advected, gpu_advected), 1e-4 * step);
  size_t moved = 0;
  for (size_t f = 0; f + 1 < setup_.sample_offsets.size(); ++f)
    for (uint32_t i = setup_.sample_offsets[f]; i < setup_.sample_offsets[f + 1]; ++i) {
      const uint32_t s0 = setup_.sample_offsets[f], s1 = setup_.sample_offsets[f + 1];
      const glm::dvec3 d = glm::normalize(before[std::min(i + 1, s1 - 1)] - before[i > s0 ? i - 1 : i]);
      const glm::dvec3 m = glm::dvec3(gpu_advected[i]) - before[i];
      ASSERT_NEAR(glm::dot(m, d), 0, 1e-4 * step) << i;
      ASSERT_LE(glm::length(m), step * (1 + 1e-5)) << i;
      moved += glm::length(m) > 0.5 * step;
    }
  EXPECT_GT(moved, before.size() / 2);

  // Smoothing of the GPU's advected samples.
  const BundleSamples smoothed = smoothReference(toDouble(gpu_advected), setup_.sample_offsets, params_.smoothing,
                                                 bundleSmoothingWindow(params_, setup_, radius), false);
  EXPECT_LT(maxDistance(smoothed, bundler.samples()), 1e-4);
}

TEST_F(GpuBundling, wholeIterationAndFinishMatchTheReference) {
  GpuBundler bundler(context());
  bundler.load(model_, setup_, params_);
  const BundleSamples original = toDouble(bundler.originalSamples());
  bundler.iterate(params_.radius);
  const BundleSamples cpu = iterateReference(original, setup_, params_, params_.radius);
  const std::vector<glm::vec4> gpu = bundler.samples();
  EXPECT_LT(maxDistance(cpu, gpu), 1e-3);
  double mean_move = 0;
  for (size_t i = 0; i < cpu.size(); ++i) mean_move += glm::length(cpu[i] - original[i]) / double(cpu.size());
  EXPECT_GT(mean_move, 0.5);  // it did move (mm), far beyond the tolerance

  // Relaxation and mapping back of the GPU's samples.
  const std::vector<float> moved = bundler.finish(model_);
  const std::vector<float> expect =
      mapBackReference(model_, setup_, original, relaxReference(original, toDouble(gpu), params_.relaxation));
  ASSERT_EQ(moved.size(), model_.positions.size());
  float worst = 0;
  for (size_t i = 0; i < moved.size(); ++i) worst = std::max(worst, std::abs(moved[i] - expect[i]));
  EXPECT_LT(worst, 1e-4f);
}

TEST_F(GpuBundling, bundlingTwiceGivesBitIdenticalPointsWithTheSameOffsets) {
  std::vector<gpu::PassTime> times;
  uint64_t bytes = 0;
  uint32_t reported = 0;
  const std::vector<float> a = bundleOnGpu(
      context(), model_, params_, [&](uint32_t done) { reported = done; }, &times, &bytes);
  const std::vector<float> b = bundleOnGpu(context(), model_, params_);
  ASSERT_EQ(a.size(), model_.positions.size());
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
  EXPECT_NE(a, model_.positions);
  EXPECT_EQ(reported, params_.iterations);
  EXPECT_GE(bytes, setup_.grid.voxelCount() * 8 + setup_.sampleCount() * 48);
  EXPECT_FALSE(times.empty());
  // The whole run stays near the reference's (float vs double over a few
  // iterations: loose, but far below the motion).
  const std::vector<float> cpu = bundleReference(model_, params_);
  double mean_err = 0, mean_move = 0;
  for (size_t i = 0; i < model_.pointCount(); ++i) {
    const glm::dvec3 g(a[3 * i], a[3 * i + 1], a[3 * i + 2]), c(cpu[3 * i], cpu[3 * i + 1], cpu[3 * i + 2]);
    const glm::dvec3 o(model_.point(i)[0], model_.point(i)[1], model_.point(i)[2]);
    mean_err += glm::length(g - c) / double(model_.pointCount());
    mean_move += glm::length(c - o) / double(model_.pointCount());
  }
  EXPECT_GT(mean_move, 1.0);
  EXPECT_LT(mean_err, 0.01 * mean_move);
}

TEST_F(GpuBundling, smallChunksGiveBitIdenticalPointsInLessMemory) {
  // The model (20-41 points a fiber, about 87 KB) is one chunk by default.
  // 1000 B chunks hold two to four fibers each, so it goes up in dozens;
  // 400 B ones are shorter than its longest fibers, which then take a chunk
  // each. The result must not depend on where the chunks fall.
  size_t longest = 0;
  for (size_t f = 0; f < model_.streamlineCount(); ++f)
    longest = std::max<size_t>(longest, model_.offsets[f + 1] - model_.offsets[f]);
  const GpuBundlerOptions small{.chunk_bytes = 1000}, tiny{.chunk_bytes = 400};
  ASSERT_GT(longest * 12, tiny.chunk_bytes);
  ASSERT_GT(model_.pointCount() * 12, 50 * small.chunk_bytes);
  uint64_t big_bytes = 0, small_bytes = 0, tiny_bytes = 0, staged_bytes = 0;
  const std::vector<float> a = bundleOnGpu(context(), model_, params_, {}, nullptr, &big_bytes);
  const std::vector<float> b = bundleOnGpu(context(), model_, params_, {}, nullptr, &small_bytes, small);
  const std::vector<float> c = bundleOnGpu(context(), model_, params_, {}, nullptr, &tiny_bytes, tiny);
  const std::vector<float> d = bundleOnGpu(context(), model_, params_, {}, nullptr, &staged_bytes,
                                           GpuBundlerOptions{.keep_stages = true});
  ASSERT_EQ(a.size(), model_.positions.size());
  ASSERT_EQ(b.size(), a.size());
  ASSERT_EQ(c.size(), a.size());
  ASSERT_EQ(d.size(), a.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
  EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(float)), 0);  // fibers over a chunk
  EXPECT_EQ(std::memcmp(a.data(), d.data(), a.size() * sizeof(float)), 0);  // the stage grids change nothing
  EXPECT_LT(small_bytes, big_bytes);
  // Every 400 B chunk is one fiber, so the chunk buffer is the longest's.
  EXPECT_EQ(big_bytes - tiny_bytes, (model_.pointCount() - longest) * 12);
  EXPECT_EQ(staged_bytes, big_bytes + setup_.grid.voxelCount() * 20);
}

TEST_F(GpuBundling, stageGridsNeedKeepStages) {
  GpuBundler bundler(context());
  bundler.load(model_, setup_, params_);
  bundler.iterate(params_.radius);
  EXPECT_THROW(bundler.counts(), Error);
  EXPECT_THROW(bundler.gradient(), Error);
  EXPECT_EQ(bundler.density().size(), setup_.grid.voxelCount());
  Tractogram other = test::wavyBundlingModel(10);
  EXPECT_THROW(bundler.finish(other), Error);
}

TEST_F(GpuBundling, anchoredEndsStayWhereTheyWere) {
  params_.anchor_ends = true;
  const std::vector<float> a = bundleOnGpu(context(), model_, params_);
  for (size_t f = 0; f < model_.streamlineCount(); ++f)
    for (const uint64_t i : {model_.offsets[f], model_.offsets[f + 1] - 1})
      for (int k = 0; k < 3; ++k) ASSERT_EQ(a[3 * i + k], model_.positions[3 * i + k]) << f;
}

TEST_F(GpuBundling, anisotropicSplatAndIterationMatchTheReference) {
  params_.mode = BundleMode::Anisotropic;
  GpuBundler bundler(context(), GpuBundlerOptions{.keep_stages = true});
  bundler.load(model_, setup_, params_);
  const BundleSamples original = toDouble(bundler.originalSamples());
  bundler.iterate(params_.radius);
  const std::vector<uint32_t> fixed = bundler.counts();
  const std::vector<double> cpu =
      splatReference(original, setup_.sample_offsets, setup_.grid, params_.radius, params_.radius * params_.anisotropy);
  double scale = 0;
  for (double v : cpu) scale = std::max(scale, v);
  ASSERT_GT(scale, 2);
  double worst = 0;
  for (size_t i = 0; i < cpu.size(); ++i)
    worst = std::max(worst, std::abs(double(fixed[i]) / shader::kBundleSplatScale - cpu[i]));
  // Float against double can round a term the other way: 1/256 each, rarely.
  EXPECT_LT(worst, 4.0 / shader::kBundleSplatScale);
  const BundleSamples expect = iterateReference(original, setup_, params_, params_.radius);
  const Agreement a = agreement(expect, original, bundler.samples());
  EXPECT_GT(a.motion, 0.2);
  EXPECT_LT(a.error, 1e-3 * a.motion + 1e-4);
}

TEST_F(GpuBundling, structureTensorAndStructureAwareIterationMatchTheReference) {
  params_.structure_aware = true;
  params_.structure_scale = 0.6;  // cells of 2 voxels: partial last cells on this grid
  GpuBundler bundler(context(), GpuBundlerOptions{.keep_stages = true});
  bundler.load(model_, setup_, params_);
  const BundleSamples original = toDouble(bundler.originalSamples());
  bundler.iterate(params_.radius);
  // The tensor from the GPU's own density, so this checks the tensor alone.
  const std::vector<float> density = bundler.density();
  const BundleTensors cpu = structureTensorReference(std::vector<double>(density.begin(), density.end()), setup_.grid,
                                                     bundleStructureCell(params_));
  const std::vector<float> gpu = bundler.structure();
  ASSERT_EQ(gpu.size(), 6 * cpu.size());
  double scale = 0, worst = 0;
  for (size_t c = 0; c < cpu.size(); ++c) {
    const glm::dmat3& j = cpu[c];
    const double expect[6] = {j[0][0], j[0][1], j[0][2], j[1][1], j[1][2], j[2][2]};
    for (int k = 0; k < 6; ++k) {
      scale = std::max(scale, std::abs(expect[k]));
      worst = std::max(worst, std::abs(expect[k] - double(gpu[6 * c + k])));
    }
  }
  ASSERT_GT(scale, 0);
  EXPECT_LT(worst, 1e-5 * scale);
  // The whole iteration, and it is not the plain one.
  const BundleSamples expect = iterateReference(original, setup_, params_, params_.radius);
  BundleParams plain = params_;
  plain.structure_aware = false;
  const BundleSamples unfiltered = iterateReference(original, setup_, plain, params_.radius);
  const Agreement a = agreement(expect, original, bundler.samples());
  double differ = 0;
  for (size_t i = 0; i < expect.size(); ++i) differ += glm::length(expect[i] - unfiltered[i]) / double(expect.size());
  EXPECT_GT(a.motion, 0.1);
  EXPECT_GT(differ, 0.05 * a.motion);
  EXPECT_LT(a.error, 1e-3 * a.motion + 1e-4);
}

TEST_F(GpuBundling, structureAwareAnisotropicIterationMatchesTheReference) {
  // The tensor of the splat's fixed-point density.
  params_.structure_aware = true;
  params_.mode = BundleMode::Anisotropic;
  GpuBundler bundler(context());
  bundler.load(model_, setup_, params_);
  const BundleSamples original = toDouble(bundler.originalSamples());
  bundler.iterate(params_.radius);
  const BundleSamples expect = iterateReference(original, setup_, params_, params_.radius);
  const Agreement a = agreement(expect, original, bundler.samples());
  EXPECT_GT(a.motion, 0.1);
  EXPECT_LT(a.error, 1e-3 * a.motion + 1e-4);
}

TEST_F(GpuBundling, structureTensorNeedsTheStructureAwareMode) {
  GpuBundler bundler(context());
  bundler.load(model_, setup_, params_);
  EXPECT_THROW(bundler.structure(), Error);
}

}  // namespace fibscope
