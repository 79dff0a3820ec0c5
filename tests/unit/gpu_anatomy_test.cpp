// Anatomical slices (shared/anatomy.h, the anatomy stage) against volumes
// nibabel writes (tests/tools/anatomy_make.py cases): a bright voxel shows
// where the camera projects nibabel's RAS position of it, on an axis-aligned
// and on an oblique, permuted, flipped sform; the grey of every pixel is the
// window applied to nibabel's value at the voxel a double-precision ray
// cast of the pixel reaches (nearest) or to the trilinear mix there; and
// slices and streamlines hide each other both ways, a translucent slice
// blending over the fibers behind it, in every pipeline. Validation on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gpu_test_context.h"
#include "io/nifti_volume.h"
#include "render/anatomy_slices.h"
#include "render/camera.h"
#include "render/gpu/anatomy.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "test_support.h"

namespace fibscope {
namespace {

using Json = nlohmann::json;

// A case of anatomy_make.py: what nibabel says of the file.
struct Case {
  std::string path;
  glm::dmat4 affine{1.0};  // nibabel's img.affine
  glm::ivec3 dims{0};
  std::vector<double> values;  // x fastest
  glm::ivec3 bright_voxel{0};
  glm::dvec3 bright_ras{0.0};

  double value(glm::ivec3 v) const { return values[(size_t(v.z) * dims.y + v.y) * dims.x + v.x]; }
};

class GpuAnatomySlices : public test::GpuTest {
 protected:
  static void SetUpTestSuite() {
    python_ = test::pythonWithNibabel();
    if (python_.empty()) return;
    dir_ = new test::TempDir;
    const auto r = test::runCommand(python_ + " " + test::toolPath("anatomy_make.py") + " cases " + dir_->path());
    made_ = r.exit_code == 0;
    output_ = r.output;
    if (made_) cases_ = Json::parse(test::readBytes(dir_->file("cases.json")));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    test::GpuTest::SetUp();
    if (IsSkipped()) return;
    if (python_.empty()) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel and numpy";
    ASSERT_TRUE(made_) << output_;
  }

  static Case readCase(const std::string& name) {
    const Json& c = cases_.at(name);
    Case k;
    k.path = dir_->file(c["file"].get<std::string>());
    const auto a = c["affine"].get<std::vector<std::vector<double>>>();
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 4; ++col) k.affine[col][row] = a[size_t(row)][size_t(col)];
    const auto shape = c["shape"].get<std::vector<int>>();
    k.dims = {shape[0], shape[1], shape[2]};
    k.values = c["values"].get<std::vector<double>>();
    if (c.contains("bright_voxel")) {
      const auto v = c["bright_voxel"].get<std::vector<int>>();
      const auto p = c["bright_ras"].get<std::vector<double>>();
      k.bright_voxel = {v[0], v[1], v[2]};
      k.bright_ras = {p[0], p[1], p[2]};
    }
    return k;
  }

  // The volume as fibscope reads and uploads it.
  GpuAnatomy upload(const Case& k) { return GpuAnatomy::upload(context(), loadAnatomyVolume(k.path)); }

  static inline std::string python_, output_;
  static inline test::TempDir* dir_ = nullptr;
  static inline bool made_ = false;
  static inline Json cases_;
};

constexpr uint32_t kWidth = 200, kHeight = 160;
const std::array<float, 3> kBackground = {0.2f, 0.4f, 0.6f};

// A camera at `distance` mm from `target` along `from`, looking at it.
Camera cameraLookingAt(glm::dvec3 target, glm::dvec3 from, double distance) {
  from = glm::normalize(from);
  // Up: any direction not along the view.
  const glm::dvec3 up = std::fabs(from.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(0, 1, 0);
  Camera c;
  const glm::dvec3 eye = target + distance * from;
  c.eye = {eye.x, eye.y, eye.z};
  c.target = {target.x, target.y, target.z};
  c.up = {up.x, up.y, up.z};
  c.near_mm = 1;
  c.far_mm = 1000;
  c.width = kWidth;
  c.height = kHeight;
  return c;
}

glm::dmat4 viewProjectionMatrix(const Camera& camera) {
  const std::array<double, 16> vp = viewProjectionD(camera);
  glm::dmat4 m;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[c][r] = vp[size_t(4 * c + r)];
  return m;
}

// Window coordinates (pixel centres at + 0.5) of world point p.
glm::dvec2 project(const Camera& camera, glm::dvec3 p) {
  const glm::dvec4 c = viewProjectionMatrix(camera) * glm::dvec4(p, 1.0);
  return {(c.x / c.w + 1) * camera.width / 2, (c.y / c.w + 1) * camera.height / 2};
}

// The eye ray through the centre of pixel (px, py), in double.
struct Ray {
  glm::dvec3 origin, direction;
};
Ray pixelRay(const Camera& camera, uint32_t px, uint32_t py) {
  const glm::dmat4 inverse = glm::inverse(viewProjectionMatrix(camera));
  const double x = (px + 0.5) / camera.width * 2 - 1, y = (py + 0.5) / camera.height * 2 - 1;
  glm::dvec4 a = inverse * glm::dvec4(x, y, 0.0, 1.0), b = inverse * glm::dvec4(x, y, 1.0, 1.0);
  a /= a.w;
  b /= b.w;
  return {glm::dvec3(camera.eye[0], camera.eye[1], camera.eye[2]), glm::normalize(glm::dvec3(b) - glm::dvec3(a))};
}

// Where the pixel's ray meets the slice of `axis` at `position` in voxel
// coordinates (nibabel's affine), and how far that lies from the volume's
// edge (in voxels, negative outside); nothing when it does not meet it in
// front of the eye.
struct SliceHit {
  glm::dvec3 q;
  double t = 0;
  double inside = 0;
};
std::optional<SliceHit> hitSlice(const Case& k, const Ray& ray, int axis, double position) {
  const glm::dmat4 to_voxel = glm::inverse(k.affine);
  const glm::dvec3 o = glm::dvec3(to_voxel * glm::dvec4(ray.origin, 1.0));
  const glm::dvec3 d = glm::dmat3(to_voxel) * ray.direction;
  if (d[axis] == 0) return std::nullopt;
  SliceHit h;
  h.t = (position - o[axis]) / d[axis];
  if (!(h.t > 0)) return std::nullopt;
  h.q = o + h.t * d;
  h.q[axis] = position;
  h.inside = INFINITY;
  for (int b = 0; b < 3; ++b) h.inside = std::min({h.inside, h.q[b] + 0.5, k.dims[b] - 0.5 - h.q[b]});
  return h;
}

// Distance of q's in-plane coordinates to the nearest voxel boundary
// (half-integer): where nearest sampling could go either way.
double boundaryDistance(glm::dvec3 q, int axis) {
  double d = INFINITY;
  for (int b = 0; b < 3; ++b)
    if (b != axis) d = std::min(d, std::fabs(q[b] - (std::floor(q[b]) + 0.5)));
  return d;
}

glm::ivec3 nearestVoxel(const Case& k, glm::dvec3 q) {
  return glm::clamp(glm::ivec3(glm::floor(q + 0.5)), glm::ivec3(0), k.dims - 1);
}

double trilinear(const Case& k, glm::dvec3 q) {
  const glm::dvec3 c = glm::clamp(q, glm::dvec3(0.0), glm::dvec3(k.dims - 1));
  const glm::ivec3 a = glm::min(glm::ivec3(glm::floor(c)), k.dims - 1), b = glm::min(a + 1, k.dims - 1);
  const glm::dvec3 f = c - glm::dvec3(a);
  double sum = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::ivec3 v((corner & 1) ? b.x : a.x, (corner & 2) ? b.y : a.y, (corner & 4) ? b.z : a.z);
    const double w = ((corner & 1) ? f.x : 1 - f.x) * ((corner & 2) ? f.y : 1 - f.y) * ((corner & 4) ? f.z : 1 - f.z);
    sum += w * k.value(v);
  }
  return sum;
}

// Window/level as the issue states it: round(255 clamp((v - lo) / (hi - lo))).
int greyOf(double v, double lo, double hi) { return int(std::lround(255 * std::clamp((v - lo) / (hi - lo), 0.0, 1.0))); }

// A unit vector perpendicular to n.
glm::dvec3 perpendicular(glm::dvec3 n) {
  const glm::dvec3 other = std::fabs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(n, other));
}

glm::dvec3 sliceNormal(const GpuAnatomy& a, int axis) {
  const PlaneEq p = slicePlane(a.grid(), axis, 0);
  return {p[0], p[1], p[2]};
}

RenderSettings sliceSettings(int shown_axis, glm::dvec3 position, SliceSampling sampling, float lo, float hi) {
  RenderSettings s;
  s.ssao = false;
  s.background = kBackground;
  s.slice_i = float(position.x);
  s.slice_j = float(position.y);
  s.slice_k = float(position.z);
  s.show_slice_i = shown_axis < 0 || shown_axis == 0;
  s.show_slice_j = shown_axis < 0 || shown_axis == 1;
  s.show_slice_k = shown_axis < 0 || shown_axis == 2;
  s.anatomy_sampling = sampling;
  s.anatomy_min = lo;
  s.anatomy_max = hi;
  return s;
}

struct Frame {
  std::vector<uint8_t> rgba;
  const uint8_t* at(uint32_t x, uint32_t y) const { return &rgba[(size_t(y) * kWidth + x) * 4]; }
  bool isBackground(uint32_t x, uint32_t y) const {
    const uint8_t* p = at(x, y);
    return p[0] == 51 && p[1] == 102 && p[2] == 153;
  }
};

// The compute pipeline draws fiblets: one fiber far outside every view here.
Tractogram farAway() {
  const float xyz[] = {5000, 0, 0, 5001, 0, 0};
  Tractogram t;
  t.addStreamline(xyz, 2);
  return t;
}

Frame renderSlices(const gpu::VulkanContext& context, FrameRenderer& renderer, const Camera& camera,
                   const RenderSettings& settings, const GpuAnatomy& anatomy) {
  static const Tractogram far_away = farAway();
  const TractogramUpload fibers = uploadTractogram(context, far_away, "far away");
  GpuScene scene(&fibers.dataset);  // the slices alone in view
  scene.anatomy = &anatomy;
  renderer.render(camera, settings, scene);
  return Frame{downloadColor(context, renderer.targets())};
}

TEST_F(GpuAnatomySlices, aBrightVoxelShowsWhereTheCameraProjectsItsRasPositionOnEverySliceAxisAlignedAndOblique) {
  FrameRenderer renderer(context(), kWidth, kHeight);
  for (const std::string name : {"bright_ras", "bright_oblique"}) {
    SCOPED_TRACE(name);
    const Case k = readCase(name);
    const GpuAnatomy anatomy = upload(k);
    const glm::dvec3 voxel(k.bright_voxel);
    for (int axis = 0; axis < 3; ++axis) {
      SCOPED_TRACE("axis " + std::to_string(axis));
      // Onto the plane at a slant, from the side its normal points to.
      const glm::dvec3 n = sliceNormal(anatomy, axis);
      const Camera camera = cameraLookingAt(k.bright_ras, n + 0.4 * perpendicular(n), 60);
      const Frame frame = renderSlices(context(), renderer, camera,
                                       sliceSettings(axis, voxel, SliceSampling::Nearest, 0, 1000), anatomy);
      double sx = 0, sy = 0;
      int bright = 0, disagree = 0;
      for (uint32_t y = 0; y < kHeight; ++y)
        for (uint32_t x = 0; x < kWidth; ++x) {
          const bool lit = frame.at(x, y)[0] > 127;
          if (lit) {
            sx += x + 0.5;
            sy += y + 0.5;
            ++bright;
          }
          // The double-precision ray cast of the same pixel.
          const std::optional<SliceHit> h = hitSlice(k, pixelRay(camera, x, y), axis, voxel[axis]);
          if (!h || std::fabs(h->inside) < 0.02 || boundaryDistance(h->q, axis) < 0.02) continue;
          const bool want = h->inside > 0 && nearestVoxel(k, h->q) == k.bright_voxel;
          disagree += lit != want;
          if (h->inside > 0) EXPECT_FALSE(frame.isBackground(x, y)) << x << "," << y;
        }
      EXPECT_EQ(disagree, 0);
      ASSERT_GE(bright, 9) << "the voxel spans a few pixels";
      const glm::dvec2 at = project(camera, k.bright_ras);
      EXPECT_NEAR(sx / bright, at.x, 1.0);
      EXPECT_NEAR(sy / bright, at.y, 1.0);
    }

    // All three slices through it: bright at its projection, dark around.
    const Camera camera = cameraLookingAt(k.bright_ras, glm::dvec3(0.8, -0.5, 0.6), 60);
    const Frame frame =
        renderSlices(context(), renderer, camera, sliceSettings(-1, voxel, SliceSampling::Nearest, 0, 1000), anatomy);
    const glm::dvec2 at = project(camera, k.bright_ras);
    EXPECT_GT(frame.at(uint32_t(at.x), uint32_t(at.y))[0], 200);
    // Farther than the projection of any corner of the voxel: dark.
    double reach = 0;
    for (int c = 0; c < 8; ++c) {
      const glm::dvec3 corner = voxel + glm::dvec3((c & 1) ? 0.5 : -0.5, (c & 2) ? 0.5 : -0.5, (c & 4) ? 0.5 : -0.5);
      reach = std::max(reach, glm::length(project(camera, glm::dvec3(k.affine * glm::dvec4(corner, 1.0))) - at));
    }
    int far_bright = 0, near_dark = 0;
    for (uint32_t y = 0; y < kHeight; ++y)
      for (uint32_t x = 0; x < kWidth; ++x) {
        const double r = glm::length(glm::dvec2(x + 0.5, y + 0.5) - at);
        if (r > reach + 1 && !frame.isBackground(x, y) && frame.at(x, y)[0] > 10) ++far_bright;
        if (r > reach + 1 && r < reach + 6 && frame.at(x, y)[0] == 0) ++near_dark;
      }
    EXPECT_EQ(far_bright, 0);
    EXPECT_GT(near_dark, 20) << "the slices are drawn (black) around the voxel";
  }
}

TEST_F(GpuAnatomySlices, theGreyOfEveryPixelIsTheWindowOfNibabelsValueNearestOrTrilinear) {
  FrameRenderer renderer(context(), kWidth, kHeight);
  const float lo = 250, hi = 1000;
  for (const std::string name : {"field_ras", "field_oblique"}) {
    const Case k = readCase(name);
    const GpuAnatomy anatomy = upload(k);
    const glm::dvec3 centre = glm::dvec3(k.dims - 1) / 2.0;
    const glm::dvec3 middle = glm::dvec3(k.affine * glm::dvec4(centre, 1.0));
    for (const SliceSampling sampling : {SliceSampling::Nearest, SliceSampling::Trilinear}) {
      for (int axis = 0; axis < 3; ++axis) {
        SCOPED_TRACE(name + (sampling == SliceSampling::Nearest ? " nearest" : " trilinear") + " axis " +
                     std::to_string(axis));
        // Trilinear between voxel planes too: a slice off the voxel centres.
        glm::dvec3 position = glm::floor(centre) + (sampling == SliceSampling::Trilinear ? 0.35 : 0.0);
        const glm::dvec3 n = sliceNormal(anatomy, axis);
        const Camera camera = cameraLookingAt(middle, -n + 0.5 * perpendicular(n), 90);
        const Frame frame = renderSlices(context(), renderer, camera, sliceSettings(axis, position, sampling, lo, hi),
                                         anatomy);
        int checked = 0, worst = 0, uncovered = 0, drawn_outside = 0;
        for (uint32_t y = 0; y < kHeight; ++y)
          for (uint32_t x = 0; x < kWidth; ++x) {
            const std::optional<SliceHit> h = hitSlice(k, pixelRay(camera, x, y), axis, position[axis]);
            if (!h || std::fabs(h->inside) < 0.02) continue;
            if (h->inside < 0) {
              drawn_outside += !frame.isBackground(x, y);
              continue;
            }
            if (frame.isBackground(x, y)) {
              ++uncovered;
              continue;
            }
            if (sampling == SliceSampling::Nearest && boundaryDistance(h->q, axis) < 0.02) continue;
            const double v = sampling == SliceSampling::Nearest ? k.value(nearestVoxel(k, h->q)) : trilinear(k, h->q);
            const uint8_t* p = frame.at(x, y);
            EXPECT_TRUE(p[0] == p[1] && p[1] == p[2]) << x << "," << y;
            worst = std::max(worst, std::abs(int(p[0]) - greyOf(v, lo, hi)));
            ++checked;
          }
        EXPECT_GT(checked, 2000);
        EXPECT_EQ(uncovered, 0);
        EXPECT_EQ(drawn_outside, 0);
        EXPECT_LE(worst, sampling == SliceSampling::Nearest ? 0 : 1);
      }
    }
  }
}

// Straight streamlines along y at x = x0, height z (mm).
void addLine(Tractogram& t, double x0, double z) {
  std::vector<float> xyz;
  for (int i = 0; i <= 160; ++i) {
    xyz.push_back(float(x0));
    xyz.push_back(float(-20.0 + 0.25 * i));
    xyz.push_back(float(z));
  }
  t.addStreamline(xyz.data(), xyz.size() / 3);
}

TEST_F(GpuAnatomySlices, slicesAndFibersHideEachOtherBothWaysAndATranslucentSliceBlendsOverTheFibersBehind) {
  const Case k = readCase("flat");  // 600 everywhere, z in [-3, 3] mm
  const GpuAnatomy anatomy = upload(k);
  Tractogram lines;
  addLine(lines, -10, 8);   // in front of the slice (seen from above)
  addLine(lines, 10, -8);   // behind it
  const TractogramUpload upload = uploadTractogram(context(), lines, "lines");
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), lines, "lines");
  Camera camera;  // the slice (60 x 60 mm) fills the view
  camera.eye = {0, 0, 80};
  camera.up = {0, 1, 0};
  camera.width = kWidth;
  camera.height = kHeight;
  FrameRenderer renderer(context(), kWidth, kHeight);
  const int grey = greyOf(600, 0, 1000);  // 153

  // Every pipeline; and with SSAO, which a slice casts on no fiber behind it.
  const std::pair<RenderPipeline, bool> variants[] = {{RenderPipeline::Compute, false},
                                                      {RenderPipeline::RawCompute, false},
                                                      {RenderPipeline::Lines, false},
                                                      {RenderPipeline::Compute, true}};
  for (const auto& [pipeline, ssao] : variants) {
    SCOPED_TRACE(std::string(renderPipelineName(pipeline)) + (ssao ? " ssao" : ""));
    RenderSettings settings = sliceSettings(2, glm::dvec3(0, 0, 1), SliceSampling::Nearest, 0, 1000);
    settings.ssao = ssao;
    settings.background = {0, 0, 0};
    settings.pipeline = pipeline;
    settings.line_width_px = 2;
    GpuScene scene(&upload.dataset, &raw);
    renderer.render(camera, settings, scene);
    const std::vector<uint8_t> fibers = downloadColor(context(), renderer.targets());
    const std::vector<shader::GBufferTexel> fiber_texels = downloadGBuffer(context(), renderer.targets());
    scene.anatomy = &anatomy;
    for (const float opacity : {1.0f, 0.5f}) {
      SCOPED_TRACE("opacity " + std::to_string(opacity));
      settings.anatomy_opacity = opacity;
      renderer.render(camera, settings, scene);
      const std::vector<uint8_t> both = downloadColor(context(), renderer.targets());
      const std::vector<shader::GBufferTexel> texels = downloadGBuffer(context(), renderer.targets());
      const double alpha = opacity == 1.0f ? 1.0 : 128.0 / 255.0;
      int front = 0, behind = 0, slice_only = 0;
      for (size_t i = 0; i < texels.size(); ++i) {
        const uint32_t f = fiber_texels[i].fiber;
        const uint8_t* before = &fibers[4 * i];
        const uint8_t* after = &both[4 * i];
        if (f == 0) {  // the fiber in front: as without the slice
          for (int c = 0; c < 3; ++c) EXPECT_EQ(after[c], before[c]) << i;
          EXPECT_EQ(texels[i].fiber, 0u);
          ++front;
        } else if (f == 1) {  // behind: hidden, or the slice's grey over it
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(after[c], alpha * grey + (1 - alpha) * before[c], 1.0)
                << i << " channel " << c << ": " << int(before[0]) << "," << int(before[1]) << "," << int(before[2])
                << " -> " << int(after[0]) << "," << int(after[1]) << "," << int(after[2]);
          EXPECT_EQ(texels[i].fiber, opacity == 1.0f ? shader::kNoFiberObject : 1u);
          ++behind;
        } else {  // nothing but the slice (all of the view): over the background
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(after[c], alpha * grey, 1.0) << i;
          EXPECT_EQ(texels[i].segment, shader::kGBufferSurface | shader::kSurfaceSourceSlice);
          ++slice_only;
        }
      }
      EXPECT_GT(front, 100);
      EXPECT_GT(behind, 100);
      EXPECT_GT(slice_only, 1000);
    }
  }
}

TEST_F(GpuAnatomySlices, theSlabFollowsTheActiveSlice) {
  const Case k = readCase("flat");
  const GpuAnatomy anatomy = upload(k);
  Tractogram lines;
  addLine(lines, -10, 2);    // within 3 mm of the slice at z = 0
  addLine(lines, 10, 12);    // 12 mm above it
  const TractogramUpload upload = uploadTractogram(context(), lines, "lines");
  Camera camera;
  camera.eye = {0, 0, 120};
  camera.up = {0, 1, 0};
  camera.width = kWidth;
  camera.height = kHeight;
  FrameRenderer renderer(context(), kWidth, kHeight);
  RenderSettings settings = sliceSettings(2, glm::dvec3(0, 0, 1), SliceSampling::Nearest, 0, 1000);
  settings.slab_mm = 6;
  settings.anatomy_opacity = 0;  // the fibers alone; the slab still follows the slice
  GpuScene scene(&upload.dataset);
  scene.anatomy = &anatomy;
  auto drawn = [&](bool follow) {
    settings.slab_follows_slice = follow;
    renderer.render(camera, settings, scene);
    std::array<int, 2> count{};
    for (const shader::GBufferTexel& t : downloadGBuffer(context(), renderer.targets()))
      if (t.fiber < 2) ++count[t.fiber];
    return count;
  };
  // The focal plane (through the target, z = 0) and the slice k = 1
  // (z = 0) agree; the slice moved to z = 12 mm keeps the other line.
  const std::array<int, 2> focal = drawn(false);
  EXPECT_GT(focal[0], 100);
  EXPECT_EQ(focal[1], 0);
  const std::array<int, 2> at_slice = drawn(true);
  EXPECT_EQ(at_slice, focal);
  settings.slice_k = 7;  // z = 12 mm
  const std::array<int, 2> moved = drawn(true);
  EXPECT_EQ(moved[0], 0);
  EXPECT_GT(moved[1], 100);
}

}  // namespace
}  // namespace fibscope
