// The raw tractogram's points split into chunks of whole streamlines
// (render/gpu/raw_tractogram.h), forced tiny here so that a few-hundred
// fiber phantom spans many of them: the chunk plan, every byte of every
// chunk, G-buffers bit for bit the same as from one chunk for both baseline
// pipelines, raw-compute still on the CPU reference, and the one-line
// errors (a streamline larger than a chunk, a chunk larger than the
// device's largest buffer). Validation layers on (GpuTest).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/raw_tractogram.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

using test::gbufferMask;
using test::renderPhantom;

using test::lineTractogram;

bool sameTexels(const std::vector<shader::GBufferTexel>& a, const std::vector<shader::GBufferTexel>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(shader::GBufferTexel)) == 0;
}

using GpuRawChunks = test::GpuTest;

TEST(GpuRawChunksPlan, chunksHoldWholeStreamlinesGreedilyInOrder) {
  // Empty streamlines join the current chunk; a chunk closes when the next
  // streamline would overflow it.
  const Tractogram t = lineTractogram({5, 0, 1, 31, 2, 40, 0, 64, 1, 3});
  const std::vector<RawChunkRange> chunks = planRawChunks("small", t.offsets, rawChunkBytes(64));
  ASSERT_EQ(chunks.size(), 4u);
  const uint64_t expected[4][4] = {{0, 5, 0, 39}, {5, 2, 39, 40}, {7, 1, 79, 64}, {8, 2, 143, 4}};
  for (size_t c = 0; c < chunks.size(); ++c) {
    SCOPED_TRACE(c);
    EXPECT_EQ(chunks[c].first_streamline, expected[c][0]);
    EXPECT_EQ(chunks[c].streamline_count, expected[c][1]);
    EXPECT_EQ(chunks[c].first_point, expected[c][2]);
    EXPECT_EQ(chunks[c].point_count, expected[c][3]);
    EXPECT_LE(rawChunkBytes(chunks[c].point_count), rawChunkBytes(64));
  }
  // No streamline, no point: one empty chunk.
  const std::vector<uint64_t> none = {0};
  const std::vector<RawChunkRange> empty = planRawChunks("empty", none, 1024);
  ASSERT_EQ(empty.size(), 1u);
  EXPECT_EQ(empty[0].point_count, 0u);
  EXPECT_EQ(empty[0].streamline_count, 0u);
  // 12 bytes a point, then the end bits in whole words.
  EXPECT_EQ(rawChunkBytes(0), 0u);
  EXPECT_EQ(rawChunkBytes(1), 16u);
  EXPECT_EQ(rawChunkBytes(32), 388u);
  EXPECT_EQ(rawChunkBytes(33), 404u);
}

TEST(GpuRawChunksPlan, aStreamlineLargerThanTheChunkLimitIsAOneLineError) {
  const Tractogram t = lineTractogram({10, 100, 10});
  try {
    planRawChunks("long.tck", t.offsets, rawChunkBytes(50));
    FAIL() << "a streamline larger than a chunk was planned";
  } catch (const Error& e) {
    const std::string what = e.what();
    std::printf("[ GPU      ] %s\n", what.c_str());
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("long.tck: ", 0), 0u) << what;
    EXPECT_NE(what.find("streamline 1 has 100 points (1.19 KiB"), std::string::npos) << what;
    EXPECT_NE(what.find("chunk limit of 608 B"), std::string::npos) << what;
  }
  EXPECT_NO_THROW(planRawChunks("long.tck", t.offsets, rawChunkBytes(100)));
}

TEST_F(GpuRawChunks, aStreamlineLargerThanTheChunkLimitIsRefusedByTheUpload) {
  const Tractogram t = lineTractogram({10, 100, 10});
  try {
    GpuRawTractogram::upload(context(), t, "long.tck", nullptr, nullptr, kDatasetStagingBytes, rawChunkBytes(99));
    FAIL() << "a streamline larger than a chunk was uploaded";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("long.tck: streamline 1 has 100 points", 0), 0u) << what;
  }
}

TEST_F(GpuRawChunks, everyChunkHoldsItsPointsAndEndBitsThroughATinyStagingBuffer) {
  const Tractogram t = lineTractogram({5, 0, 1, 31, 2, 40, 0, 64, 1, 3});
  const GpuRawTractogram raw =
      GpuRawTractogram::upload(context(), t, "small", nullptr, nullptr, 48, rawChunkBytes(64));
  const std::vector<RawChunkRange> plan = planRawChunks("small", t.offsets, rawChunkBytes(64));
  ASSERT_EQ(raw.chunkCount(), plan.size());
  std::vector<shader::RawChunk> table(raw.chunkCount());
  gpu::downloadFromBuffer(context(), raw.chunkTable(), table.data(), table.size() * sizeof(shader::RawChunk));
  for (uint32_t c = 0; c < raw.chunkCount(); ++c) {
    SCOPED_TRACE(c);
    const GpuRawTractogram::Chunk& chunk = raw.chunk(c);
    const uint64_t n = plan[c].point_count;
    EXPECT_EQ(chunk.entry.first_point, plan[c].first_point);
    EXPECT_EQ(chunk.entry.point_count, n);
    EXPECT_EQ(chunk.entry.first_streamline, plan[c].first_streamline);
    EXPECT_EQ(chunk.entry.streamline_count, plan[c].streamline_count);
    EXPECT_EQ(chunk.entry.points, chunk.buffer.address);
    EXPECT_EQ(chunk.entry.ends, chunk.buffer.address + 12 * n);
    EXPECT_EQ(std::memcmp(&table[c], &chunk.entry, sizeof(shader::RawChunk)), 0);
    std::vector<float> points(3 * n);
    gpu::downloadFromBuffer(context(), chunk.buffer, points.data(), points.size() * sizeof(float));
    EXPECT_EQ(points, std::vector<float>(t.positions.begin() + 3 * plan[c].first_point,
                                         t.positions.begin() + 3 * (plan[c].first_point + n)));
    // End bits by chunk-local point index.
    std::vector<uint32_t> ends((n + 31) / 32), expected(ends.size(), 0);
    gpu::downloadFromBuffer(context(), chunk.buffer, ends.data(), ends.size() * sizeof(uint32_t), 12 * n);
    for (uint64_t s = plan[c].first_streamline; s < plan[c].first_streamline + plan[c].streamline_count; ++s) {
      if (t.pointsIn(s) == 0) continue;
      const uint64_t last = t.offsets[s + 1] - 1 - plan[c].first_point;
      expected[last / 32] |= 1u << (last % 32);
    }
    EXPECT_EQ(ends, expected);
  }
  shader::RawTractogram block{};
  gpu::downloadFromBuffer(context(), raw.blockBuffer(), &block, sizeof(block));
  EXPECT_EQ(block.chunks, raw.chunkTable().address);
  EXPECT_EQ(block.chunk_count, raw.chunkCount());
  EXPECT_EQ(block.point_count, t.pointCount());
  EXPECT_EQ(block.streamline_count, t.streamlineCount());
}

TEST_F(GpuRawChunks, manySmallChunksDrawTheSameGBuffersAsOne) {
  constexpr uint32_t kSize = 160;
  const Tractogram fibers = renderPhantom(300, 11);
  const GpuRawTractogram one = GpuRawTractogram::upload(context(), fibers, "phantom");
  const GpuRawTractogram many =
      GpuRawTractogram::upload(context(), fibers, "phantom", nullptr, nullptr, kDatasetStagingBytes, 64 << 10);
  ASSERT_EQ(one.chunkCount(), 1u);
  ASSERT_GT(many.chunkCount(), 8u);
  EXPECT_EQ(many.segmentCount(), one.segmentCount());
  std::printf("[ GPU      ] %u streamlines, %llu points: %u chunks of at most 64 KiB\n", many.streamlineCount(),
              (unsigned long long)many.pointCount(), many.chunkCount());
  const Bounds bounds = tractogramBounds(fibers);
  const Camera views[] = {standardView(bounds, StandardView::Sagittal, kSize, kSize),
                          orbitCamera(bounds, 37, 23, kSize, kSize, 0.45)};
  FrameRenderer renderer(context(), kSize, kSize);
  RenderSettings settings;
  for (RenderPipeline pipeline : {RenderPipeline::RawCompute, RenderPipeline::Lines}) {
    settings.pipeline = pipeline;
    for (float width : {1.0f, 3.0f}) {
      settings.line_width_px = width;
      for (size_t v = 0; v < std::size(views); ++v) {
        SCOPED_TRACE(std::string(renderPipelineName(pipeline)) + ", width " + std::to_string(width) + ", view " +
                     std::to_string(v));
        renderer.render(views[v], settings, GpuScene{nullptr, &one});
        const std::vector<shader::GBufferTexel> single = downloadGBuffer(context(), renderer.targets());
        const FrameStats stats = renderer.render(views[v], settings, GpuScene{nullptr, &many});
        const std::vector<shader::GBufferTexel> chunked = downloadGBuffer(context(), renderer.targets());
        EXPECT_EQ(stats.segments_total, one.segmentCount());
        size_t covered = 0;
        for (const shader::GBufferTexel& texel : single) covered += texel.fiber != shader::kNoFiberId;
        ASSERT_GT(covered, size_t(kSize) * kSize / 20) << "the view shows the phantom";
        EXPECT_TRUE(sameTexels(single, chunked));
        if (pipeline != RenderPipeline::RawCompute) continue;
        // And still the CPU reference's pixels (the same bar as
        // GpuBaselines.rawComputeMatchesTheCpuReferenceFromEveryView).
        const ReferenceFrame reference = rasterizeReference(fibers, views[v], width);
        const CoverageComparison c = compareCoverage(gbufferMask(chunked), reference.coverageMask(), kSize, kSize);
        EXPECT_GE(c.agreement, 0.98) << c.summary();
        EXPECT_LE(c.maxDistance(), 1.0) << c.summary();
        size_t both = 0, same_segment = 0;
        for (size_t i = 0; i < chunked.size(); ++i) {
          if (chunked[i].fiber == shader::kNoFiberId || reference.fiber[i] == kNoFiber) continue;
          ++both;
          same_segment += chunked[i].fiber == reference.fiber[i] && chunked[i].segment == reference.point[i];
        }
        EXPECT_GE(double(same_segment), 0.99 * double(both));
      }
    }
  }
}

TEST_F(GpuRawChunks, anEmptyTractogramDrawsNothing) {
  const Tractogram t = lineTractogram({});
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), t, "empty");
  EXPECT_EQ(raw.chunkCount(), 1u);
  Camera camera;
  camera.eye = {0, 0, 200};
  camera.width = camera.height = 32;
  FrameRenderer renderer(context(), 32, 32);
  RenderSettings settings;
  for (RenderPipeline pipeline : {RenderPipeline::RawCompute, RenderPipeline::Lines}) {
    settings.pipeline = pipeline;
    renderer.render(camera, settings, GpuScene{nullptr, &raw});
    for (const shader::GBufferTexel& texel : downloadGBuffer(context(), renderer.targets()))
      ASSERT_EQ(texel.fiber, shader::kNoFiberId);
  }
}

}  // namespace
}  // namespace fibscope
