// SVO straight tubes in a whole frame (the standard stages with the SVO
// stage before the merge): tube pixels reach the G-buffer as surfaces
// where the tubes are nearer than the lines and stay lines where the lines
// are nearer, as the brute-force tube reference and the reference line
// raster say, and picking a tube pixel names its fiber and the SVO as the
// source. Validation layers on.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gpu_test_context.h"
#include "tube_test_scenes.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "render/gpu/pick.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/tractogram_upload.h"
#include "render/image_compare.h"
#include "render/reference_raster.h"
#include "shared/gbuffer.h"
#include "shared/render_config.h"
#include "svo/gpu/gpu_svo.h"
#include "svo/svo_reference.h"

namespace fibscope {
namespace {

class GpuSvoFrame : public test::GpuTest {};

TEST_F(GpuSvoFrame, tubesAndLinesOccludeEachOtherAndPickingNamesTheTube) {
  const test::LinesAndTubesScene setup = test::linesAndTubesScene(0.5f, 96, 72);
  const Tractogram& lines = setup.lines;
  const TubeModel model = buildTubes(setup.tubes, setup.options);
  constexpr uint32_t w = 96, h = 72;
  const Camera& camera = setup.camera;
  const ReferenceFrame line_ref = rasterizeReference(lines, camera, 2.0f);
  const TubeReferenceImage tube_ref = renderBruteForceCapsules(model, camera);
  std::vector<uint8_t> want_tube(size_t(w) * h), want_line(size_t(w) * h);
  size_t lines_over_tubes = 0, tubes_over_lines = 0;
  for (size_t i = 0; i < want_tube.size(); ++i) {
    const bool t = tube_ref.fiber[i] != shader::kNoFiberId, l = line_ref.fiber[i] != kNoFiber;
    want_tube[i] = t && (!l || tube_ref.depth[i] < line_ref.depth[i]);
    want_line[i] = l && !want_tube[i];
    lines_over_tubes += t && want_line[i];
    tubes_over_lines += l && want_tube[i];
  }
  ASSERT_GT(lines_over_tubes, 30u);
  ASSERT_GT(tubes_over_lines, 30u);

  const TractogramUpload upload = uploadTractogram(context(), lines, "lines");
  const GpuRawTractogram raw = GpuRawTractogram::upload(context(), lines, "lines");
  GpuTubes tubes = uploadTubes(context(), model);
  GpuSvo svo;
  try {
    svo = uploadSvo(context(), buildSvoGpu(context(), model, tubes, chooseSvoGrid(model, 0.0f)));
    FrameRenderer renderer(context(), w, h, withSvoStage(standardFrameStages(), &svo, &tubes));
    const GpuScene scene(&upload.dataset, &raw);
    RenderSettings settings;
    settings.line_width_px = 2.0f;
    renderer.render(camera, settings, scene);
    const auto texels = downloadGBuffer(context(), renderer.targets());
    std::vector<uint8_t> got_tube, got_line;
    for (const shader::GBufferTexel& t : texels) {
      const bool tube = t.segment == (shader::kGBufferSurface | shader::kSurfaceSourceSvo);
      got_tube.push_back(tube);
      got_line.push_back(!tube && t.fiber != shader::kNoFiberId);
    }
    const CoverageComparison ct = compareCoverage(got_tube, want_tube, w, h);
    const CoverageComparison cl = compareCoverage(got_line, want_line, w, h);
    EXPECT_GE(ct.agreement, 0.98) << "tubes: " << ct.summary();
    EXPECT_LE(ct.maxDistance(), 1.0) << "tubes: " << ct.summary();
    EXPECT_GE(cl.agreement, 0.98) << "lines: " << cl.summary();
    EXPECT_LE(cl.maxDistance(), 1.0) << "lines: " << cl.summary();
    bool picked = false;
    for (size_t i = 0; i < got_tube.size() && !picked; ++i)
      if (got_tube[i] && want_tube[i] && tube_ref.fiber[i] == 1u) {
        const PickResult pick = pickFiber(context(), renderer.targets(), uint32_t(i % w), uint32_t(i / w));
        EXPECT_TRUE(pick.hit && pick.surface);
        EXPECT_EQ(pick.fiber, 1u);
        EXPECT_EQ(pick.source, shader::kSurfaceSourceSvo);
        picked = true;
      }
    EXPECT_TRUE(picked);
  } catch (...) {
    destroySvo(context(), svo);
    destroyTubes(context(), tubes);
    throw;
  }
  destroySvo(context(), svo);
  destroyTubes(context(), tubes);
}

}  // namespace
}  // namespace fibscope
