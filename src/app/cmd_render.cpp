// `fibscope render [FILE] [--pipeline ...] [--culling ...] [--view V |
// --camera AZ,EL,DIST] [--size WxH] [--color ...] [--lighting ...] -o PNG`:
// one frame, headless, to a PNG. Reads (or generates) the tractogram,
// compresses it to fiblets in memory (a .fbl is uploaded as stored),
// renders, and writes the image; prints where the time went.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <memory>
#include <optional>
#include <string>

#include "app/anatomy_options.h"
#include "app/commands.h"
#include "app/render_options.h"
#include "app/render_scene.h"
#include "app/scene_cuts.h"
#include "app/scene_filter.h"
#include "app/tube_options.h"
#include "core/error.h"
#include "io/png_writer.h"
#include "render/camera.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/frame_stages.h"
#include "svo/gpu/gpu_distance_field.h"
#include "svo/gpu/gpu_svo.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {
namespace {

struct RenderCommandOptions {
  RenderCliOptions render;
  TubeCliOptions tubes;
  std::string view;
  std::string camera;
  std::string output;
  float voxel_mm = 0.0f;  // --voxel (svo-straight, svo-curved); 0: chosen from the data
  bool voxel_given = false;
  std::string svo_lod_px;  // --svo-lod-px (svo-straight, svo-curved); empty: 0, off
};

// `--pipeline svo-straight` (issue 16): the fibers of --tubes (all by
// default) as straight streamtubes ray-traced from a sparse voxel octree,
// over the compute pipeline's lines (each line lies inside its tube; the
// fibers left out of --tubes stay lines). `--pipeline svo-curved`: the same
// with each segment the tube around its cubic Hermite centre line,
// sphere-traced in the octree's leaves.

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

Camera cameraFor(const RenderCommandOptions& o, const LoadedScene& scene, uint32_t width, uint32_t height) {
  const Bounds& bounds = scene.bounds;
  // Views are framed snugly: the tractogram within 90 % of the image.
  if (!o.view.empty()) {
    StandardView view = StandardView::Sagittal;
    if (o.view == "coronal") view = StandardView::Coronal;
    else if (o.view == "axial") view = StandardView::Axial;
    else if (o.view != "sagittal") throw Error("--view: expected sagittal, coronal or axial, got '" + o.view + "'");
    return snugCamera(scene.sample, [&](double f) { return standardView(bounds, view, width, height, f); });
  }
  // Default: a three-quarter view from the front left and above, the
  // tractogram framed snugly (distance 0 below).
  double azimuth = 125, elevation = 20, distance = 0;
  if (!o.camera.empty()) {
    char rest = 0;
    if (std::sscanf(o.camera.c_str(), "%lf,%lf,%lf%c", &azimuth, &elevation, &distance, &rest) != 3 ||
        !(distance == 0 || (distance > 0.01 && distance < 1000)) || !(elevation >= -90 && elevation <= 90))
      throw Error("--camera: expected AZ,EL,DIST (degrees, degrees in [-90, 90], distance factor > 0.01 where 1 "
                  "fits the bounding sphere, or 0 to frame the tractogram snugly), got '" + o.camera + "'");
  }
  if (distance == 0)
    return snugCamera(scene.sample, [&](double f) { return orbitCamera(bounds, azimuth, elevation, width, height, f); });
  return orbitCamera(bounds, azimuth, elevation, width, height, distance);
}

void runRender(RenderCommandOptions o) {
  const auto start = Clock::now();
  if (o.output.size() < 5 || o.output.substr(o.output.size() - 4) != ".png")
    throw Error("-o: the output must be a .png file, got '" + o.output + "'");
  if (!o.view.empty() && !o.camera.empty()) throw Error("--view and --camera: give one of them");
  const auto pipeline = o.render.values.find("pipeline");
  const int svo_kind = pipeline != o.render.values.end() ? svoPipelineKind(pipeline->second) : -1;
  const bool svo = svo_kind >= 0, svo_curved = svo_kind == 1;
  if (svo) {
    o.render.values["pipeline"] = "compute";
    useSvoTubeDefaults(o.tubes);
  }
  if (o.voxel_given && !svo) throw Error("--voxel: only with --pipeline svo-straight or svo-curved");
  if (o.voxel_given && !(o.voxel_mm > 0.0f && std::isfinite(o.voxel_mm)))
    throw Error("--voxel: expected a voxel size > 0 mm, got " + std::to_string(o.voxel_mm));
  if (!o.svo_lod_px.empty() && !svo) throw Error("--svo-lod-px: only with --pipeline svo-straight or svo-curved");
  const std::vector<float> lods = o.svo_lod_px.empty() ? std::vector<float>{0.0f} : parseSvoLodPx(o.svo_lod_px);
  if (lods.size() != 1) throw Error("--svo-lod-px: render takes one value, got '" + o.svo_lod_px + "'");
  const SvoTraceOptions trace_options{lods[0]};
  RenderSettings settings = renderSettingsFrom(o.render);
  const FilterCriteria criteria = criteriaFrom(o.render.criteria).criteria;  // bad specs before any work
  uint32_t width = 0, height = 0;
  parseFrameSize(o.render.size, width, height);
  const std::optional<NiftiVolume> volume = readAnatomyOption(o.render);  // a bad file before any work

  // The instance, the device and the frame renderer's pipelines (lavapipe
  // compiles every shader with LLVM here) take ~0.15 s on one core: made on
  // a second thread during the first pass over the file, which reads on
  // one core. loadScene waits for them only when it uploads.
  // The tubes' buffers: the tube stage reads them at every frame (filled
  // below, released by `tubes_owner` before the device goes).
  GpuTubes tubes;
  GpuSvo svo_tree;
  // The tubes' distance field (--ao-method df, --df-shadows): built with
  // the tubes, read by the distance-field stage.
  GpuDistanceField distance_field;
  const bool wants_field =
      (svo || o.tubes.requested()) && (distanceFieldAoRuns(settings) || distanceFieldShadowsRun(settings));
  struct Device {
    std::unique_ptr<gpu::VulkanContext> context;
    std::unique_ptr<FrameRenderer> renderer;  // destroyed before the context
  };
  std::future<Device> making = std::async(std::launch::async, [&o, &settings, &tubes, &svo_tree, &distance_field,
                                                               svo, wants_field, width, height, trace_options] {
    Device d;
    d.context = createRenderContext(o.render);
    FrameStageList stages =
        svo ? withSvoStage(standardFrameStages(), &svo_tree, &tubes, trace_options)
            : (o.tubes.requested() ? withTubeStage(standardFrameStages(), &tubes) : standardFrameStages());
    if (wants_field) stages = withDistanceFieldStage(std::move(stages), &distance_field);
    d.renderer = std::make_unique<FrameRenderer>(*d.context, width, height, std::move(stages));
    d.renderer->prepare(settings);  // this frame's shader variants
    return d;
  });
  std::optional<Device> device;
  auto waitForDevice = [&]() -> const gpu::VulkanContext& {
    if (!device) device = making.get();
    return *device->context;
  };
  SceneOptions scene_options;
  scene_options.path = o.render.input;
  scene_options.phantom_streamlines = o.render.phantom_streamlines;
  scene_options.upload_raw = !drawsFiblets(settings.pipeline);
  scene_options.fiber_scalars = criteria.scalar_ranges;
  LoadedScene scene = loadScene(waitForDevice, scene_options);
  const gpu::VulkanContext& context = waitForDevice();
  // With --tubes-dim-rest the tube fibers are the selection (the other
  // lines dimmed by --dim), unless the filter's dimming selects
  // already.
  gpu::Buffer tube_selection;
  struct TubesOwner {
    const gpu::VulkanContext& context;
    GpuTubes& tubes;
    GpuSvo& svo;
    GpuDistanceField& field;
    gpu::Buffer& selection;
    ~TubesOwner() {
      gpu::destroyBuffer(context, selection);
      destroyDistanceField(context, field);
      destroySvo(context, svo);
      destroyTubes(context, tubes);
    }
  } tubes_owner{context, tubes, svo_tree, distance_field, tube_selection};
  GpuScene gpu_scene = scene.gpuScene();
  applyScalarColoring(context, scene.fiblets, o.render, settings, gpu_scene);
  const SceneFilter filter(context, scene, criteria, o.render.dim_dropped);
  filter.apply(gpu_scene, settings.pipeline);
  if (settings.color == ColorMode::Scalar && !o.render.gave("scalar-range"))
    filter.distanceRange(settings.scalar_min, settings.scalar_max);  // colour by distance: its range
  TubeBuildStats tube_stats;
  SvoGpuBuildStats svo_stats;
  std::string svo_line;
  std::vector<uint32_t> tube_words;
  if (o.tubes.requested()) {
    std::vector<uint32_t> kept;
    if (filter.active()) kept = filter.keptFibers();
    const TubeModel model = loadTubeModel(o.render.input, o.render.phantom_streamlines, o.tubes, &tube_stats,
                                          filter.active() ? &kept : nullptr);
    tubes = uploadTubes(context, model);
    if (svo) {
      SvoGpuBuildOptions build;
      build.progress = true;
      const SvoGrid grid = chooseSvoGrid(model, o.voxel_mm, svo_curved, svoMemoryLimit(context, build));
      const SvoTree tree = buildSvoGpu(context, model, tubes, grid, build, &svo_stats);
      svo_tree = uploadSvo(context, tree);
      svo_line = svoBuildSummary(model, tree, svo_stats);
    }
    if (wants_field) distance_field = buildDistanceFieldGpu(context, tubes, chooseDistanceFieldGrid(model, settings.df_voxel_mm));
    if (o.tubes.dim_rest && !o.render.dim_dropped) {
      tube_words.assign((scene.streamlines + 31) / 32, 0u);
      for (const TubeModel::Tube& t : model.tubes)
        if (t.fiber / 32 < tube_words.size()) tube_words[t.fiber / 32] |= 1u << (t.fiber % 32);
    }
  }
  if (!tube_words.empty() && gpu_scene.selection_bits == 0) {
    tube_selection = gpu::createBuffer(context, tube_words.size() * sizeof(uint32_t), gpu::MemoryUse::DeviceLocal);
    gpu::uploadToBuffer(context, tube_selection, tube_words.data(), tube_words.size() * sizeof(uint32_t));
    gpu_scene.selection_bits = tube_selection.address;
  }
  const SceneCuts cuts(context, o.render);
  cuts.apply(gpu_scene);
  GpuAnatomy anatomy;
  if (volume) {
    RenderSettings* fitted[] = {&settings};
    applyAnatomy(context, *volume, o.render, fitted, anatomy, gpu_scene);
  }
  const Camera camera = withAnatomyInView(cameraFor(o, scene, width, height), anatomy);
  auto t = Clock::now();
  FrameRenderer& renderer = *device->renderer;
  const FrameStats stats = renderer.render(camera, settings, gpu_scene);
  const std::vector<uint8_t> rgba = downloadColor(context, renderer.targets());
  const double frame_seconds = secondsSince(t);
  t = Clock::now();
  writePngRgba(o.output, width, height, rgba);
  const double png_seconds = secondsSince(t);
  checkValidation(context, o.render);
  std::printf("%s: %llu streamlines, %llu segments -> %s (%ux%u, %s pipeline, %s culling)\n", scene.name.c_str(),
              static_cast<unsigned long long>(scene.streamlines), static_cast<unsigned long long>(scene.segments),
              o.output.c_str(), width, height, std::string(renderPipelineName(settings.pipeline)).c_str(),
              std::string(cullingModeName(settings.culling)).c_str());
  if (svo) {
    double trace_ms = 0;
    for (const PassTiming& p : stats.passes)
      if (p.name == "svo trace") trace_ms += p.ms;
    if (trace_options.lod_px > 0.0f)
      std::printf("%s; trace %.1f ms (lod %g px)\n", svo_line.c_str(), trace_ms, double(trace_options.lod_px));
    else
      std::printf("%s; trace %.1f ms\n", svo_line.c_str(), trace_ms);
  } else if (o.tubes.requested()) {
    double tube_ms = 0;
    for (const PassTiming& p : stats.passes)
      if (isTubePass(p.name)) tube_ms += p.ms;
    const std::string radius = o.tubes.radius_from.empty()
                                   ? "radius " + std::to_string(o.tubes.radius_mm) + " mm"
                                   : "radius from " + o.tubes.radius_from + " (" + o.tubes.radius_range + " mm)";
    std::printf("tubes: %llu fibers, %llu nodes (of %llu points, within %.4f mm), %u segments, %s, "
                "drawn by %s in %.1f ms",
                static_cast<unsigned long long>(tube_stats.tubes), static_cast<unsigned long long>(tube_stats.nodes),
                static_cast<unsigned long long>(tube_stats.input_points), o.tubes.tolerance(), tubes.segment_count,
                radius.c_str(), std::string(tubeMethodName(settings.tube_method)).c_str(), tube_ms);
    if (tube_stats.invalid_radii > 0)
      std::printf(", %llu non-finite radius values drawn at the smallest radius",
                  static_cast<unsigned long long>(tube_stats.invalid_radii));
    if (settings.tube_method == TubeMethod::Compute)
      std::printf(", %llu tiles overflowed", static_cast<unsigned long long>(stats.tube_tiles_overflowed));
    std::printf("\n");
  }
  if (wants_field) {
    double ao_ms = 0, shadow_ms = 0;
    for (const PassTiming& p : stats.passes) {
      if (p.name == "df ao") ao_ms += p.ms;
      if (p.name == "df shadow") shadow_ms += p.ms;
    }
    const DistanceFieldGrid& g = distance_field.grid;
    std::printf("distance field: voxel %.3f mm, %ux%ux%u (%.1f MB), band %.2f mm, built in %.3f s; df ao %.2f ms, "
                "df shadow %.2f ms\n",
                g.voxel, g.size.x, g.size.y, g.size.z, double(g.bytes()) / 1e6, g.band, distance_field.build_s, ao_ms,
                shadow_ms);
  }
  if (filter.active())
    std::printf("filter: %llu of %llu fibers kept (%s), %.2f ms on the GPU\n",
                static_cast<unsigned long long>(filter.kept()), static_cast<unsigned long long>(filter.fibers()),
                o.render.dim_dropped ? "the rest dimmed" : "the rest hidden", filter.gpuMilliseconds());
  std::printf("time: read %.3f s, compress %.3f s, upload %.3f s, frame %.3f s (GPU %.1f ms), png %.3f s, total "
              "%.3f s\n",
              scene.read_seconds, scene.encode_seconds, scene.upload_seconds, frame_seconds, stats.gpu_ms,
              png_seconds, secondsSince(start));
}

}  // namespace

void addRenderCommand(CLI::App& app) {
  auto o = std::make_shared<RenderCommandOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render one frame of a tractogram (or the built-in phantom) to a PNG");
  // One frame has no previous frame to learn visibility from: two-phase
  // culling would draw everything in its first phase and then only add a
  // depth pyramid and a second cull. The frustum test and LoD still pay.
  o->render.defaults.culling = CullingMode::Frustum;
  // So that nobody mistakes left for right (--no-orientation-labels).
  o->render.defaults.orientation_labels = true;
  addRenderCliOptions(cmd, o->render);
  addTubeCliOptions(cmd, o->tubes);
  cmd->add_option("--voxel", o->voxel_mm,
                  "Voxel size of the octree in mm, with --pipeline svo-straight or svo-curved (default: from the tube radius "
                  "and the step, coarser where the octree would not fit the device's memory)")
      ->each([o](const std::string&) { o->voxel_given = true; });
  cmd->add_option("--svo-lod-px", o->svo_lod_px, std::string(kSvoLodHelp) + " [default 0]");
  cmd->add_option("--view", o->view, "sagittal | coronal | axial");
  cmd->add_option("--camera", o->camera, "AZ,EL,DIST: orbit angles in degrees and distance factor (0: framed snugly, 1: the bounding sphere fits)");
  cmd->add_option("-o,--output", o->output, "Output PNG")->required();
  cmd->callback([o] { runRender(*o); });
}

}  // namespace fibscope
