// The fiber filter on the GPU (select/gpu/gpu_fiber_filter.h): its kept
// bits equal the CPU filter's verdicts (select/fiber_filter.h, tckedit's
// semantics) fiber for fiber, on the fiblets' decoded points (the CPU
// decoder's sequential order) and on a raw tractogram's own points, for
// spheres, boxes, oriented boxes, ends-only, ordered includes, length
// limits and per-fiber scalar ranges (with NaN values); and the renderer draws only kept fibers in every pipeline, with
// two-phase culling still exact while the filter changes between frames.
// Validation layers on (GpuTest fails on any message).
#include <gtest/gtest.h>

#include <bit>
#include <glm/glm.hpp>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "codec/fiblet_decoder.h"
#include "codec/fiblet_encoder.h"
#include "gpu/buffer.h"
#include "gpu_render_test_support.h"
#include "gpu_test_context.h"
#include "render/camera.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "select/fiber_filter.h"
#include "select/gpu/gpu_fiber_filter.h"
#include "select/region.h"
#include "select/scalar_range.h"
#include "select/voxel_mask.h"

namespace fibscope {
namespace {

bool bitSet(const std::vector<uint32_t>& words, size_t i) { return (words[i / 32] >> (i % 32) & 1u) != 0; }

// A named set of criteria placed relative to the phantom's box.
struct Case {
  std::string name;
  FilterCriteria criteria;
};

std::string num(double v) { return std::to_string(v); }

// A mask on an oblique grid of 2.5 mm voxels (rotated 25 degrees about z
// and 10 about x) around (cx, cy, cz): the voxels of a ball of `radius` mm,
// every seventh one left out, so its boundary is ragged.
Region obliqueMask(double cx, double cy, double cz, double radius) {
  auto mask = std::make_shared<VoxelMask>();
  mask->path = "oblique-mask.nii";
  const int n = int(std::ceil(2 * radius / 2.5)) + 3;
  for (int k = 0; k < 3; ++k) mask->size[k] = n;
  const double a = glm::radians(25.0), b = glm::radians(10.0), voxel = 2.5;
  // voxel -> world: R * v * voxel + origin, origin so that the grid's centre is (cx, cy, cz).
  const glm::dmat3 rz(std::cos(a), std::sin(a), 0, -std::sin(a), std::cos(a), 0, 0, 0, 1);
  const glm::dmat3 rx(1, 0, 0, 0, std::cos(b), std::sin(b), 0, -std::sin(b), std::cos(b));
  const glm::dmat3 linear = rz * rx * voxel;
  const glm::dvec3 origin = glm::dvec3(cx, cy, cz) - linear * glm::dvec3(0.5 * (n - 1));
  const glm::dmat3 inv = glm::inverse(linear);
  const glm::dvec3 t = -(inv * origin);
  for (int i = 0; i < 3; ++i)
    mask->world_to_voxel[i] = {float(inv[0][i]), float(inv[1][i]), float(inv[2][i]), float(t[i])};
  mask->bits.assign((size_t(n) * n * n + 31) / 32, 0);
  size_t index = 0;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x, ++index) {
        const glm::dvec3 w = linear * glm::dvec3(x, y, z) + origin;
        if (glm::length(w - glm::dvec3(cx, cy, cz)) <= radius && index % 7 != 3) {
          mask->bits[index / 32] |= 1u << (index % 32);
          ++mask->set_voxels;
        }
      }
  return MaskRegion{mask->path, mask};
}

std::vector<Case> casesFor(const Bounds& b) {
  const double cx = 0.5 * (b.min[0] + b.max[0]), cy = 0.5 * (b.min[1] + b.max[1]), cz = 0.5 * (b.min[2] + b.max[2]);
  const double ex = b.max[0] - b.min[0], ey = b.max[1] - b.min[1], ez = b.max[2] - b.min[2];
  auto sphere = [&](double fx, double fy, double fz, double fr) {
    return parseRegion("sphere:" + num(cx + fx * ex) + "," + num(cy + fy * ey) + "," + num(cz + fz * ez) + "," +
                       num(fr * ex));
  };
  auto box = [&](double fx0, double fy0, double fz0, double fx1, double fy1, double fz1) {
    return parseRegion("box:" + num(cx + fx0 * ex) + "," + num(cy + fy0 * ey) + "," + num(cz + fz0 * ez) + "," +
                       num(cx + fx1 * ex) + "," + num(cy + fy1 * ey) + "," + num(cz + fz1 * ez));
  };
  const Region obox = parseRegion("obox:" + num(cx) + "," + num(cy + 0.1 * ey) + "," + num(cz) + "," + num(0.5 * ex) +
                                  "," + num(0.15 * ey) + "," + num(0.2 * ez) + ",20,-35,50");
  std::vector<Case> cases;
  auto add = [&](std::string name, auto&& fill) {
    Case c{std::move(name), {}};
    fill(c.criteria);
    cases.push_back(std::move(c));
  };
  add("include sphere", [&](FilterCriteria& c) { c.include = {sphere(0, 0, 0.1, 0.12)}; });
  add("include sphere, exclude box", [&](FilterCriteria& c) {
    c.include = {sphere(0, 0, 0.1, 0.15)};
    c.exclude = {box(-0.5, -0.5, -0.5, 0.5, -0.1, 0.5)};
  });
  add("two includes", [&](FilterCriteria& c) { c.include = {sphere(0, 0, 0.1, 0.15), box(-0.5, -0.5, 0.3, 0.5, 0.5, 0.5)}; });
  add("oriented box", [&](FilterCriteria& c) { c.include = {obox}; });
  add("ends only", [&](FilterCriteria& c) {
    c.include = {box(-0.5, -0.5, 0.1, 0.5, 0.5, 0.5)};
    c.ends_only = true;
  });
  add("ordered includes", [&](FilterCriteria& c) {
    c.include_ordered = {box(-0.5, -0.5, 0.2, 0.5, 0.5, 0.5), box(-0.5, -0.5, -0.5, 0.5, 0.5, -0.1)};
  });
  add("ordered, ends only, exclude", [&](FilterCriteria& c) {
    c.include_ordered = {box(-0.5, -0.5, 0.0, 0.5, 0.5, 0.5), box(-0.5, -0.5, -0.5, 0.5, 0.5, 0.0)};
    c.exclude = {sphere(0.3, 0, 0, 0.1)};
    c.ends_only = true;
  });
  add("include mask", [&](FilterCriteria& c) { c.include = {obliqueMask(cx, cy, cz + 0.1 * ez, 0.12 * ex)}; });
  add("exclude mask, ends only", [&](FilterCriteria& c) {
    c.exclude = {obliqueMask(cx, cy, cz + 0.35 * ez, 0.2 * ex)};
    c.ends_only = true;
  });
  add("ordered masks", [&](FilterCriteria& c) {
    c.include_ordered = {obliqueMask(cx, cy, cz + 0.3 * ez, 0.25 * ex), obliqueMask(cx, cy, cz - 0.2 * ez, 0.25 * ex)};
  });
  add("within 15 mm of a point", [&](FilterCriteria& c) {
    c.distance_zone = SphereRegion{{float(cx + 0.1 * ex), float(cy), float(cz + 0.2 * ez)}, 0.0f};
    c.max_distance_mm = 0.1 * ex;
  });
  add("near an oriented box, ends-only include", [&](FilterCriteria& c) {
    c.distance_zone = obox;
    c.max_distance_mm = 0.05 * ex;
    c.include = {box(-0.5, -0.5, 0.0, 0.5, 0.5, 0.5)};
    c.ends_only = true;
  });
  add("length limits", [&](FilterCriteria& c) {
    c.min_length_mm = 0.4 * ex;
    c.max_length_mm = 0.9 * ex;
  });
  add("length and exclude", [&](FilterCriteria& c) {
    c.min_length_mm = 0.3 * ex;
    c.exclude = {sphere(0, 0, 0, 0.1)};
  });
  return cases;
}

class GpuFiberFilterTest : public test::GpuTest {
 protected:
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    fibers_ = test::renderPhantom(400, 5);
    bounds_ = tractogramBounds(fibers_);
    upload_ = std::make_unique<TractogramUpload>(uploadTractogram(context(), fibers_, "phantom"));
    // The points the GPU filter sees: the serial decode (the CPU decoder's
    // sequential order), and the lengths the dataset was uploaded with.
    const EncodedFiblets encoded = encodeTractogram(fibers_, upload_->params);
    decoded_ = FibletDecoder(upload_->params).decodeAll(encoded, DecodeOrder::Sequential);
    lengths_ = streamlineLengths(fibers_);
    filter_ = std::make_unique<GpuFiberFilter>(context());
  }
  void TearDown() override {
    filter_.reset();
    upload_.reset();
    test::GpuTest::TearDown();
  }
  FilterFibletSource source() const {
    const GpuDataset& d = upload_->dataset;
    return {d.blockAddress(), d.block().fiblet_count, d.block().fiber_count, 0, d.fiberLength().address};
  }
  // Fibers where the GPU's bit and the CPU's verdict on `points` differ.
  static size_t mismatches(const std::vector<uint32_t>& words, const FiberFilter& cpu, const Tractogram& points,
                           const std::vector<float>& lengths, size_t& kept) {
    size_t differ = 0;
    kept = 0;
    for (size_t f = 0; f < points.streamlineCount(); ++f) {
      const bool want = cpu.evaluate(points.point(points.offsets[f]), points.pointsIn(f), lengths[f]).kept();
      kept += want;
      if (want != bitSet(words, f)) ++differ;
    }
    return differ;
  }

  Tractogram fibers_, decoded_;
  Bounds bounds_;
  std::vector<float> lengths_;
  std::unique_ptr<TractogramUpload> upload_;
  std::unique_ptr<GpuFiberFilter> filter_;
};

TEST_F(GpuFiberFilterTest, keptBitsOfFibletsEqualTheCpuFilterOnTheDecodedPoints) {
  ASSERT_EQ(decoded_.streamlineCount(), fibers_.streamlineCount());
  const FilterFibletSource src = source();
  for (const Case& c : casesFor(bounds_)) {
    SCOPED_TRACE(c.name);
    const FiberFilter cpu(c.criteria, 0.1f);
    ASSERT_TRUE(filter_->update(cpu, std::span(&src, 1), src.fibers));
    const std::vector<uint32_t> words = filter_->keptWords();
    ASSERT_EQ(words.size(), (src.fibers + 31) / 32);
    size_t kept = 0;
    EXPECT_EQ(mismatches(words, cpu, decoded_, lengths_, kept), 0u);
    EXPECT_EQ(filter_->keptCount(), kept);
    if (c.criteria.distance_zone) {
      // Each fiber's distance for colouring: the CPU's, to the rounding of
      // the GPU's square root.
      ASSERT_NE(filter_->zoneDistances(), 0u);
      const std::vector<float> gpu_mm = filter_->zoneDistanceValues();
      ASSERT_EQ(gpu_mm.size(), src.fibers);
      size_t far = 0;
      for (size_t f = 0; f < gpu_mm.size(); ++f) {
        const float want = cpu.zoneDistance(decoded_.point(decoded_.offsets[f]), decoded_.pointsIn(f));
        far += !(std::fabs(gpu_mm[f] - want) <= 1e-4f * (1.0f + want));
      }
      EXPECT_EQ(far, 0u);
    }
    // Each case keeps some fibers and drops others, so it could fail.
    EXPECT_GT(kept, 0u);
    EXPECT_LT(kept, fibers_.streamlineCount());
    std::printf("%-28s kept %zu of %zu fibers, %.2f ms on the GPU\n", c.name.c_str(), kept, fibers_.streamlineCount(),
                filter_->lastGpuMilliseconds());
  }
}

TEST_F(GpuFiberFilterTest, keptBitsOfARawTractogramEqualTheCpuFilterOnTheFilesPoints) {
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
  gpu::Buffer lengths = gpu::createBuffer(context(), lengths_.size() * sizeof(float), gpu::MemoryUse::DeviceLocal);
  gpu::uploadToBuffer(context(), lengths, lengths_.data(), lengths_.size() * sizeof(float));
  const FilterRawSource src{raw.blockAddress(), raw.streamlineCount(), raw.pointCount(), lengths.address};
  for (const Case& c : casesFor(bounds_)) {
    SCOPED_TRACE(c.name);
    const FiberFilter cpu(c.criteria, 0.1f);
    ASSERT_TRUE(filter_->update(cpu, src));
    size_t kept = 0;
    EXPECT_EQ(mismatches(filter_->keptWords(), cpu, fibers_, lengths_, kept), 0u);
    EXPECT_EQ(filter_->keptCount(), kept);
    EXPECT_GT(kept, 0u);
    EXPECT_LT(kept, fibers_.streamlineCount());
    EXPECT_NE(filter_->keptPointBits(), 0u);
  }
  gpu::destroyBuffer(context(), lengths);
}

// Per-fiber values for scalar ranges: "a" uniform in [0, 1) with every
// 23rd NaN (dropped whatever the range), "b" a fiber's length in mm (so
// its ranges correlate with the regions' cases), as the file's arrays.
std::vector<std::vector<float>> fiberScalars(const std::vector<float>& lengths) {
  std::vector<std::vector<float>> v(2);
  uint32_t x = 12345;
  for (size_t f = 0; f < lengths.size(); ++f) {
    x = x * 1664525u + 1013904223u;
    v[0].push_back(f % 23 == 4 ? NAN : float(x >> 8) / float(1 << 24));
    v[1].push_back(lengths[f]);
  }
  return v;
}

// The cases of casesFor with scalar ranges added, and ranges alone.
std::vector<Case> scalarCasesFor(const Bounds& b) {
  const double ex = b.max[0] - b.min[0];
  std::vector<Case> cases;
  auto add = [&](std::string name, FilterCriteria c, std::vector<ScalarRange> ranges) {
    c.scalar_ranges = std::move(ranges);
    cases.push_back({std::move(name), std::move(c)});
  };
  add("a in [0.25, 0.75]", {}, {{"a", 0, 0.25, 0.75}});
  add("a >= 0.5 (open max)", {}, {{"a", 0, 0.5, NAN}});
  add("a open both ends (NaN dropped)", {}, {{"a", 0, NAN, NAN}});
  add("b <= 0.6 x extent, a <= 0.9", {}, {{"b", 0, NAN, 0.6 * ex}, {"a", 0, NAN, 0.9}});
  const std::vector<Case> regions = casesFor(b);
  for (size_t i : {size_t(1), size_t(5), size_t(10), size_t(12)})
    add(regions[i].name + ", a in [0.1, 0.8]", regions[i].criteria, {{"a", 0, 0.1, 0.8}});
  return cases;
}

TEST_F(GpuFiberFilterTest, scalarRangesKeepTheFibersTheCpuFilterKeepsOnFibletsAndRawVertices) {
  const std::vector<std::vector<float>> values = fiberScalars(lengths_);
  const FilterFibletSource src = source();
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
  gpu::Buffer lengths = gpu::createBuffer(context(), lengths_.size() * sizeof(float), gpu::MemoryUse::DeviceLocal);
  gpu::uploadToBuffer(context(), lengths, lengths_.data(), lengths_.size() * sizeof(float));
  const FilterRawSource raw_src{raw.blockAddress(), raw.streamlineCount(), raw.pointCount(), lengths.address};
  auto cpuKept = [&](const FiberFilter& cpu, const Tractogram& points, std::vector<uint8_t>& kept) {
    std::vector<float> scalars;
    kept.assign(points.streamlineCount(), 0);
    for (size_t f = 0; f < points.streamlineCount(); ++f) {
      scalars.clear();
      for (const ScalarRange& r : cpu.criteria().scalar_ranges) scalars.push_back(values[r.name == "a" ? 0 : 1][f]);
      kept[f] = cpu.evaluate(points.point(points.offsets[f]), points.pointsIn(f), lengths_[f], scalars).kept();
    }
  };
  for (const Case& c : scalarCasesFor(bounds_)) {
    SCOPED_TRACE(c.name);
    const FiberFilter cpu(c.criteria, 0.1f);
    std::vector<std::vector<float>> used;
    for (const ScalarRange& r : c.criteria.scalar_ranges) used.push_back(values[r.name == "a" ? 0 : 1]);
    for (bool on_raw : {false, true}) {
      SCOPED_TRACE(on_raw ? "raw vertices" : "fiblets");
      ASSERT_TRUE(on_raw ? filter_->update(cpu, raw_src, used)
                         : filter_->update(cpu, std::span(&src, 1), src.fibers, used));
      const std::vector<uint32_t> words = filter_->keptWords();
      std::vector<uint8_t> want;
      cpuKept(cpu, on_raw ? fibers_ : decoded_, want);
      size_t differ = 0, kept = 0;
      for (size_t f = 0; f < want.size(); ++f) {
        kept += want[f];
        differ += bool(want[f]) != bitSet(words, f);
      }
      EXPECT_EQ(differ, 0u);
      EXPECT_EQ(filter_->keptCount(), kept);
      EXPECT_GT(kept, 0u);
      EXPECT_LT(kept, fibers_.streamlineCount());
    }
  }
  // The values' count must match the ranges and the fibers.
  FilterCriteria c;
  c.scalar_ranges = {{"a", 0, 0.2, 0.4}};
  EXPECT_THROW(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers), Error);
  const std::vector<std::vector<float>> short_values = {std::vector<float>(3, 0.3f)};
  EXPECT_THROW(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers, short_values), Error);
  // Other values for the same criteria: updated (the same ones again: not).
  const std::vector<std::vector<float>> first = {values[0]}, second = {std::vector<float>(src.fibers, 0.3f)};
  EXPECT_TRUE(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers, first));
  EXPECT_FALSE(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers, first));
  EXPECT_TRUE(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers, second));
  EXPECT_EQ(filter_->keptCount(), src.fibers) << "every value 0.3 lies in [0.2, 0.4]";
  gpu::destroyBuffer(context(), lengths);
}

TEST_F(GpuFiberFilterTest, updatesOnlyWhenACriterionChangesAndAnEmptyFilterKeepsAll) {
  const FilterFibletSource src = source();
  FilterCriteria c;
  c.include = {parseRegion("sphere:0,0,0,20")};
  EXPECT_TRUE(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers));
  EXPECT_NE(filter_->keptBits(), 0u);
  EXPECT_FALSE(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers)) << "same criteria: no GPU work";
  c.include = {parseRegion("sphere:0,0,0,21")};
  EXPECT_TRUE(filter_->update(FiberFilter(c), std::span(&src, 1), src.fibers)) << "a sphere grew";
  EXPECT_TRUE(filter_->update(FiberFilter(FilterCriteria{}), std::span(&src, 1), src.fibers));
  EXPECT_EQ(filter_->keptBits(), 0u) << "nothing to filter: everything drawn";
  EXPECT_EQ(filter_->keptCount(), src.fibers);
  // Too many regions for the GPU's 64 hit bits: an error, nothing kept half-way.
  FilterCriteria many;
  for (int i = 0; i < 40; ++i) many.include.push_back(parseRegion("sphere:0,0,0," + std::to_string(i + 1)));
  for (int i = 0; i < 30; ++i) many.exclude.push_back(parseRegion("sphere:50,0,0," + std::to_string(i + 1)));
  EXPECT_THROW(filter_->update(FiberFilter(many), std::span(&src, 1), src.fibers), Error);
}

// What a frame drew: per pixel the fiber (kNoFiberId where none).
std::vector<uint32_t> drawnFibers(const gpu::VulkanContext& context, const FrameRenderer& renderer) {
  std::vector<uint32_t> fibers;
  for (const shader::GBufferTexel& t : downloadGBuffer(context, renderer.targets())) fibers.push_back(t.fiber);
  return fibers;
}

TEST_F(GpuFiberFilterTest, everyPipelineDrawsOnlyKeptFibersAndTwoPhaseCullingStaysExact) {
  constexpr uint32_t kSize = 128;
  const Camera camera = orbitCamera(bounds_, 30, 20, kSize, kSize, 1.0);
  const FilterFibletSource src = source();
  const std::vector<Case> cases = casesFor(bounds_);
  RenderSettings none, two_phase;
  none.culling = CullingMode::None;
  two_phase.culling = CullingMode::TwoPhase;
  none.ssao = two_phase.ssao = false;
  none.lod_pixels = two_phase.lod_pixels = 0;
  FrameRenderer reference(context(), kSize, kSize), culled(context(), kSize, kSize);
  size_t unfiltered_pixels = 0;
  {
    reference.render(camera, none, GpuScene{&upload_->dataset});
    for (uint32_t f : drawnFibers(context(), reference)) unfiltered_pixels += f != shader::kNoFiberId;
  }
  // The culled renderer keeps its two-phase history across the filter's
  // changes: the cases follow each other frame after frame.
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const FiberFilter cpu(c.criteria, 0.1f);
    filter_->update(cpu, std::span(&src, 1), src.fibers);
    const std::vector<uint32_t> words = filter_->keptWords();
    GpuScene scene{&upload_->dataset};
    scene.kept_bits = filter_->keptBits();
    reference.render(camera, none, scene);
    culled.render(camera, two_phase, scene);
    const auto a = downloadVisibility(context(), reference.targets());
    const auto b = downloadVisibility(context(), culled.targets());
    size_t key_diff = 0;
    for (size_t i = 0; i < a.size(); ++i) key_diff += a[i] != b[i];
    EXPECT_EQ(key_diff, 0u) << "two-phase culling on versus off with the filter";
    size_t drawn = 0, dropped_drawn = 0;
    for (uint32_t f : drawnFibers(context(), reference)) {
      if (f == shader::kNoFiberId) continue;
      ++drawn;
      dropped_drawn += !bitSet(words, f);
    }
    EXPECT_EQ(dropped_drawn, 0u) << "a dropped fiber was drawn";
    EXPECT_LT(drawn, unfiltered_pixels);
  }

  // The baselines: the raw tractogram's kept bits, per streamline and per point.
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), fibers_, "phantom");
  gpu::Buffer lengths = gpu::createBuffer(context(), lengths_.size() * sizeof(float), gpu::MemoryUse::DeviceLocal);
  gpu::uploadToBuffer(context(), lengths, lengths_.data(), lengths_.size() * sizeof(float));
  const FilterRawSource raw_src{raw.blockAddress(), raw.streamlineCount(), raw.pointCount(), lengths.address};
  const FiberFilter cpu(cases[1].criteria, 0.1f);
  filter_->update(cpu, raw_src);
  const std::vector<uint32_t> words = filter_->keptWords();
  for (RenderPipeline pipeline : {RenderPipeline::RawCompute, RenderPipeline::Lines}) {
    SCOPED_TRACE(pipeline == RenderPipeline::Lines ? "lines" : "raw-compute");
    RenderSettings settings = none;
    settings.pipeline = pipeline;
    GpuScene scene{nullptr, &raw};
    reference.render(camera, settings, scene);
    size_t all = 0;
    for (uint32_t f : drawnFibers(context(), reference)) all += f != shader::kNoFiberId;
    scene.kept_bits = filter_->keptBits();
    scene.kept_point_bits = filter_->keptPointBits();
    reference.render(camera, settings, scene);
    size_t drawn = 0, dropped_drawn = 0;
    for (uint32_t f : drawnFibers(context(), reference)) {
      if (f == shader::kNoFiberId) continue;
      ++drawn;
      dropped_drawn += !bitSet(words, f);
    }
    EXPECT_EQ(dropped_drawn, 0u);
    EXPECT_GT(drawn, 0u);
    EXPECT_LT(drawn, all);
  }
  gpu::destroyBuffer(context(), lengths);
}

}  // namespace
}  // namespace fibscope
