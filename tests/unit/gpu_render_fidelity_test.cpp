// The compute pipeline against the CPU reference rasteriser of the raw
// polylines (paper fig. 8; src/render/reference_raster.h is the pixel
// contract): on a phantom, from the three standard views and an oblique
// one, at line widths 1 and 3, every covered pixel of one image lies within
// 1 px of a covered pixel of the other and >= 98 % of covered pixels agree.
// Validation layers on (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "codec/codec_params.h"
#include "codec/fiblet_encoder.h"
#include "gpu/submit.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "render/camera.h"
#include "render/gpu/fiblet_passes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/scene_table.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/render_config.h"

namespace fibscope {
namespace {

using test::gbufferMask;
using test::renderPhantom;
using test::unpackTangent;

class GpuRenderFidelity : public test::GpuTest {};

TEST_F(GpuRenderFidelity, computePipelineMatchesTheCpuReferenceFromEveryView) {
  const Tractogram fibers = renderPhantom(400, 5);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  const Bounds bounds = tractogramBounds(fibers);
  constexpr uint32_t kSize = 200;
  FrameRenderer renderer(context(), kSize, kSize);
  RenderSettings settings;
  settings.culling = CullingMode::None;
  struct View {
    const char* name;
    Camera camera;
  };
  const View views[] = {{"sagittal", standardView(bounds, StandardView::Sagittal, kSize, kSize)},
                        {"coronal", standardView(bounds, StandardView::Coronal, kSize, kSize)},
                        {"axial", standardView(bounds, StandardView::Axial, kSize, kSize)},
                        {"oblique, close", orbitCamera(bounds, 37, 23, kSize, kSize, 0.45)}};
  for (float width : {1.0f, 3.0f}) {
    settings.line_width_px = width;
    for (const View& view : views) {
      SCOPED_TRACE(std::string(view.name) + ", width " + std::to_string(width));
      renderer.render(view.camera, settings, GpuScene{&upload.dataset});
      const auto texels = downloadGBuffer(context(), renderer.targets());
      const ReferenceFrame reference = rasterizeReference(fibers, view.camera, width);
      const CoverageComparison c =
          compareCoverage(gbufferMask(texels), reference.coverageMask(), kSize, kSize);
      ASSERT_GT(c.covered_b, kSize * kSize / 20) << "the view shows the phantom: " << c.summary();
      std::printf("%s %.0f: %s\n", view.name, width, c.summary().c_str());
      EXPECT_GE(c.agreement, 0.98) << c.summary();
      EXPECT_LE(c.maxDistance(), 1.0) << c.summary();
      // Where both cover a pixel, the same fiber wins almost everywhere
      // (the decoded points are micrometres off the raw ones, so ties in
      // depth can fall either way).
      size_t both = 0, same_fiber = 0;
      for (size_t i = 0; i < texels.size(); ++i) {
        if (texels[i].fiber == shader::kNoFiberId || reference.fiber[i] == kNoFiber) continue;
        ++both;
        same_fiber += texels[i].fiber == reference.fiber[i];
      }
      EXPECT_GE(double(same_fiber), 0.95 * double(both)) << same_fiber << " of " << both;
    }
  }
}

// The raster's lanes per fiblet: one (a serial decode, CPU devices' default)
// or 8 to 64 with the paper's parallel prefix; every width, with the scan in
// shared memory or by subgroup shuffles, must draw the same image.
TEST_F(GpuRenderFidelity, everyRasterWidthMatchesTheReference) {
  const Tractogram fibers = renderPhantom(300, 21);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  constexpr uint32_t kSize = 160;
  const Camera camera = orbitCamera(tractogramBounds(fibers), 200, -30, kSize, kSize, 0.7);
  const ReferenceFrame reference = rasterizeReference(fibers, camera, 2.0f);
  GpuFrameTargets frame = createFrameTargets(context(), kSize, kSize);
  std::vector<uint8_t> first_mask;
  struct Variant {
    uint32_t lanes;
    RasterScan scan;
  };
  std::vector<Variant> variants = {{1, RasterScan::Auto},  // serial decode (CPU devices' default)
                                   {8, RasterScan::SharedMemory},
                                   {16, RasterScan::SharedMemory},
                                   {32, RasterScan::SharedMemory},
                                   {64, RasterScan::SharedMemory}};
  // The subgroup scan where the device's subgroups allow it (lavapipe: 8).
  const uint32_t subgroup = context().info().subgroup_size;
  if (context().info().subgroup_shuffle_relative && (subgroup == 8 || subgroup == 16 || subgroup == 32 || subgroup == 64))
    variants.push_back({subgroup, RasterScan::Subgroup});
  for (const Variant& variant : variants) {
    const uint32_t lanes = variant.lanes;
    SCOPED_TRACE("lanes " + std::to_string(lanes) + (variant.scan == RasterScan::Subgroup ? ", subgroup scan" : ""));
    FibletPasses passes = createFibletPasses(context(), lanes, variant.scan);
    gpu::Buffer table = createSceneTableBuffer(context());  // the one dataset at bases 0
    const GpuDataset* datasets[] = {&upload.dataset};
    const SceneLayout layout = sceneLayout(datasets);
    // Raster + resolve alone (no culling, no shading), as a frame records them.
    auto drawAndResolve = [&] {
      gpu::submitOnce(context(), [&](VkCommandBuffer cmd) {
        const shader::CameraBlock block = makeCameraBlock(camera, 2.0f);
        vkCmdUpdateBuffer(cmd, frame.camera.buffer, 0, sizeof(block), &block);
        vkCmdFillBuffer(cmd, frame.visibility.buffer, 0, VK_WHOLE_SIZE, 0xFFFFFFFFu);
        recordSceneTableUpdate(cmd, table, layout);
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                           VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        recordFibletRasterAll(cmd, context(), passes, upload.dataset, frame);
        gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                           VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                           VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
        recordFibletResolve(cmd, passes, table.address, frame);
      });
      return downloadGBuffer(context(), frame);
    };
    const std::vector<shader::GBufferTexel> decoded = drawAndResolve();
    // The same frame with the tangent cache: the resolve reads the rasters'
    // tangents instead of decoding; the texels must agree (tangents to the
    // packing's precision: computed in world and in normalised space).
    prepareTangentCache(context(), frame, upload.dataset.block().fiblet_count);
    ASSERT_NE(frame.tangents.address, 0u);
    const std::vector<shader::GBufferTexel> cached = drawAndResolve();
    prepareTangentCache(context(), frame, 0);
    size_t covered = 0, differ = 0;
    for (size_t i = 0; i < decoded.size(); ++i) {
      ASSERT_EQ(decoded[i].fiber, cached[i].fiber) << i;
      ASSERT_EQ(decoded[i].segment, cached[i].segment) << i;
      if (decoded[i].fiber == shader::kNoFiberId) continue;
      ++covered;
      const auto a = unpackTangent(decoded[i].tangent), b = unpackTangent(cached[i].tangent);
      differ += std::fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) < 0.99999;
    }
    EXPECT_EQ(differ, 0u) << "of " << covered << " covered pixels have different tangents";
    gpu::destroyBuffer(context(), table);
    destroyFibletPasses(context(), passes);
    const std::vector<uint8_t> mask = gbufferMask(decoded);
    const CoverageComparison c = compareCoverage(mask, reference.coverageMask(), kSize, kSize);
    EXPECT_GE(c.agreement, 0.98) << c.summary();
    EXPECT_LE(c.maxDistance(), 1.0) << c.summary();
    if (first_mask.empty()) first_mask = mask;
    // The runs compose in different orders, so points may move by float
    // rounding: a pixel or two at most.
    const CoverageComparison between = compareCoverage(mask, first_mask, kSize, kSize);
    EXPECT_GE(between.agreement, 0.999) << between.summary();
  }
  destroyFrameTargets(context(), frame);
}

TEST_F(GpuRenderFidelity, onTheFlyUploadEncodesInParallelLikeTheSequentialEncoder) {
  // 700 fibers of ~880 points: three chunks of 2^18 points, so the parts
  // encoded by different workers are joined.
  const Tractogram fibers = renderPhantom(700, 9);
  ASSERT_GT(fibers.pointCount(), size_t(2) << 18);
  const TractogramUpload upload = uploadTractogram(context(), fibers, "phantom");
  const EncodedFiblets expected = encodeTractogram(fibers, upload.params);
  std::vector<uint8_t> records(expected.bytes.size());
  ASSERT_EQ(upload.dataset.block().fiblet_count, expected.fibletCount());
  gpu::downloadFromBuffer(context(), upload.dataset.records(), records.data(), records.size());
  EXPECT_TRUE(records == expected.bytes);
  std::vector<uint32_t> first(expected.fiberCount() + 1);
  gpu::downloadFromBuffer(context(), upload.dataset.fiberFirstFiblet(), first.data(), first.size() * 4);
  for (size_t f = 0; f < expected.fiberCount(); ++f) ASSERT_EQ(first[f], expected.fiber_first_fiblet[f]) << f;
}

TEST_F(GpuRenderFidelity, streamedUploadEqualsTheInMemoryOne) {
  // Two passes over a reader (what `render FILE` does for the compute
  // pipeline) against the whole tractogram in memory: same parameters,
  // records, tables, box and counts.
  PhantomOptions options;
  options.streamlines = 700;
  options.step_mm = 0.1;
  options.seed = 9;
  options.threads = 1;
  const Tractogram fibers = readAllStreamlines(*openPhantom(options));
  const StreamedUpload streamed = uploadStreamed(context(), [&] { return openPhantom(options); }, "phantom");
  const CodecParams params = chooseCodecParams(fibers);
  EXPECT_EQ(streamed.upload.params.delta, params.delta);
  EXPECT_EQ(streamed.upload.params.alpha, params.alpha);
  EXPECT_EQ(streamed.upload.params.scale, params.scale);
  EXPECT_EQ(streamed.streamlines, fibers.streamlineCount());
  EXPECT_EQ(streamed.points, fibers.pointCount());
  const Bounds box = tractogramBounds(fibers);
  EXPECT_EQ(streamed.bounds.min, box.min);
  EXPECT_EQ(streamed.bounds.max, box.max);
  EXPECT_GT(streamed.sample.size(), 1000u);
  const EncodedFiblets expected = encodeTractogram(fibers, params);
  ASSERT_EQ(streamed.upload.dataset.block().fiblet_count, expected.fibletCount());
  std::vector<uint8_t> records(expected.bytes.size());
  gpu::downloadFromBuffer(context(), streamed.upload.dataset.records(), records.data(), records.size());
  EXPECT_TRUE(records == expected.bytes);
  std::vector<float> lengths(fibers.streamlineCount());
  gpu::downloadFromBuffer(context(), streamed.upload.dataset.fiberLength(), lengths.data(), lengths.size() * 4);
  EXPECT_TRUE(lengths == streamlineLengths(fibers));
}

}  // namespace
}  // namespace fibscope
