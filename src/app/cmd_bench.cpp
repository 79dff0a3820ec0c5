// `fibscope bench [FILE] [--pipeline P] [--culling C] [--compare P[/C],...]
// [--frames N] [--step DEG] [--size WxH] [--count-missed] [--json]`: the fiblets paper's
// frame benchmark (section 5): 1920x1080, the camera orbiting the
// tractogram at 1.14 degrees per frame for a full turn (316 frames), GPU
// timestamps around every pass. Prints mean / median / p95 frame time, the
// time of each pass, the fraction of fiblets drawn and segments drawn per
// millisecond; with --compare, several pipelines draw the same frames in one
// run (frame by frame, in turn) and their ratios to the first are printed.
// --count-missed also draws every measured frame with culling off (untimed)
// and counts, per occlusion-culled compute variant, the pixels covered
// there but not in its frame: zero for two-phase, the artifact of the
// coverage buffer (CullingMode::Coverage, paper figure 9).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <numeric>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "app/anatomy_options.h"
#include "app/commands.h"
#include "app/render_options.h"
#include "app/render_scene.h"
#include "app/scene_cuts.h"
#include "app/scene_filter.h"
#include "app/tube_options.h"
#include "core/error.h"
#include "render/camera.h"
#include "render/gpu/fiblet_mesh_pass.h"
#include "render/gpu/frame_renderer.h"
#include "svo/gpu/gpu_svo.h"
#include "tubes/gpu/gpu_tubes.h"

namespace fibscope {
namespace {

struct BenchOptions {
  RenderCliOptions render;
  std::string compare;
  // Spline tubes (issue 15 item 5): --tubes draws them in every variant;
  // --tube-compare M1,M2,... draws each variant once per tube method
  // (compute, raycast, tess), all on the same frames.
  TubeCliOptions tubes;
  std::string tube_compare;
  // SVO streamtubes (issue 16 item 5): --pipeline (or a --compare entry)
  // svo-straight | svo-curved draws the fibers of --tubes (all by default)
  // ray-traced from the octree over the compute pipeline's lines; --voxel
  // as render's.
  float voxel_mm = 0.0f;
  // --svo-lod-px PX[,PX...]: the SVO trace's level of detail, each svo
  // variant once per value (empty: 0, off).
  std::string svo_lod_px;
  uint32_t frames = 316;
  double step_deg = 1.14;
  double elevation_deg = 0;
  double distance = 0;  // 0: the closest that frames the box at every azimuth
  uint32_t warmup = 2;
  // 0: every frame of the orbit. N: N frames spread evenly over it, each
  // after an unmeasured frame one step before it, so two-phase culling sees
  // the previous frame the full orbit would have shown it; the fractions
  // drawn estimate the full orbit's at 2N / frames of its cost.
  uint32_t sample = 0;
  uint32_t filter_evaluations = 1;
  bool count_missed = false;
  bool json = false;
};

struct OrbitFrame {
  double azimuth_deg = 0;
  bool measured = false;
};

// The frames rendered, in order: the warm-up at the first frame's camera,
// then the orbit or its sample.
std::vector<OrbitFrame> orbitFrames(const BenchOptions& o) {
  std::vector<OrbitFrame> frames(o.warmup, OrbitFrame{0.0, false});
  if (o.sample == 0) {
    for (uint32_t i = 0; i < o.frames; ++i) frames.push_back({o.step_deg * double(i), true});
    return frames;
  }
  for (uint32_t j = 0; j < o.sample; ++j) {
    const uint64_t index = uint64_t(j) * o.frames / o.sample;
    // The orbit's first frame follows the warm-up at its own camera.
    frames.push_back({o.step_deg * (index == 0 ? 0.0 : double(index) - 1.0), false});
    frames.push_back({o.step_deg * double(index), true});
  }
  return frames;
}

struct Variant {
  std::string label;  // "compute/two-phase"
  bool tubes = false;  // draws the tubes (--tubes; "none" in --tube-compare: not)
  int svo = -1;        // the octree it traces: 0 straight, 1 curved; -1 none
  float svo_lod_px = 0;  // its trace's level of detail (0: off)
  RenderSettings settings;
  std::vector<double> gpu_ms, wall_ms, drawn_fraction, lod_fraction, tube_ms;
  uint64_t tube_method_bytes = 0;  // the largest seen
  std::map<std::string, double> pass_ms_sum;
  std::vector<std::string> pass_order;
  uint64_t segments_drawn_sum = 0;
  std::vector<uint64_t> missed_pixels;   // --count-missed: per measured frame
  std::vector<uint64_t> changed_pixels;  // ... and keys that differ at all (another fiber shows)
};

// Pixels the reference keys cover that `keys` leave empty, and pixels whose
// keys differ at all.
void countMissed(const std::vector<uint64_t>& reference, const std::vector<uint64_t>& keys, Variant& v) {
  uint64_t missed = 0, changed = 0;
  for (size_t i = 0; i < reference.size() && i < keys.size(); ++i) {
    missed += reference[i] != ~uint64_t(0) && keys[i] == ~uint64_t(0);
    changed += reference[i] != keys[i];
  }
  v.missed_pixels.push_back(missed);
  v.changed_pixels.push_back(changed);
}


// "a,b,,c" -> {"a", "b", "", "c"} (an empty item is the parser's to refuse).
std::vector<std::string> commaSeparated(const std::string& text) {
  std::vector<std::string> items;
  for (size_t start = 0;;) {
    const size_t comma = text.find(',', start);
    items.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return items;
    start = comma + 1;
  }
}

std::vector<Variant> variantsFrom(BenchOptions o) {
  // --pipeline svo-*: the compute pipeline's lines under the octree's tubes.
  std::string base_spec;
  if (const auto p = o.render.values.find("pipeline"); p != o.render.values.end() && svoPipelineKind(p->second) >= 0) {
    base_spec = p->second;
    p->second = "compute";
  }
  const RenderSettings base = renderSettingsFrom(o.render);
  std::vector<std::string> specs;
  if (o.compare.empty()) {
    specs.push_back(!base_spec.empty() ? base_spec
                                       : std::string(renderPipelineName(base.pipeline)) + "/" +
                                             std::string(cullingModeName(base.culling)));
  } else {
    specs = commaSeparated(o.compare);
  }
  const std::vector<std::string> tube_methods = o.tube_compare.empty() ? std::vector<std::string>()
                                                                       : commaSeparated(o.tube_compare);
  if (!tube_methods.empty() && !o.tubes.requested())
    throw Error("--tube-compare: give the tubes to draw (--tubes FIBERS|all|filtered)");
  const std::vector<float> lods = o.svo_lod_px.empty() ? std::vector<float>{0.0f} : parseSvoLodPx(o.svo_lod_px);
  std::vector<Variant> variants;
  for (const std::string& spec : specs) {
    Variant v;
    v.settings = base;
    const size_t slash = spec.find('/');
    if (const int kind = svoPipelineKind(spec.substr(0, slash)); kind >= 0) {
      if (!tube_methods.empty()) throw Error("--tube-compare: not with " + spec + " (its tubes come from the octree)");
      v.svo = kind;
      v.settings.pipeline = RenderPipeline::Compute;
      if (slash != std::string::npos) v.settings.culling = parseCullingMode(spec.substr(slash + 1));
      v.label = spec.substr(0, slash) + "/" + std::string(cullingModeName(v.settings.culling));
      for (const float lod : lods) {
        Variant l = v;
        l.svo_lod_px = lod;
        if (!o.svo_lod_px.empty()) {
          char text[32];
          std::snprintf(text, sizeof(text), " lod %g px", double(lod));
          l.label += text;
        }
        variants.push_back(std::move(l));
      }
      continue;
    }
    v.settings.pipeline = parseRenderPipeline(spec.substr(0, slash));
    if (slash != std::string::npos) v.settings.culling = parseCullingMode(spec.substr(slash + 1));
    v.label = std::string(renderPipelineName(v.settings.pipeline));
    if (drawsFiblets(v.settings.pipeline)) v.label += "/" + std::string(cullingModeName(v.settings.culling));
    if (tube_methods.empty()) {
      v.tubes = o.tubes.requested();
      if (v.tubes) v.label += " tubes " + std::string(tubeMethodName(v.settings.tube_method));
      variants.push_back(std::move(v));
      continue;
    }
    for (const std::string& method : tube_methods) {
      Variant t = v;
      // "none": the same frames without tubes, so the wall time's
      // difference is the tubes' where timestamps are not trusted.
      t.tubes = method != "none";
      if (t.tubes) t.settings.tube_method = parseTubeMethod(method);
      t.label += " tubes " + (t.tubes ? std::string(tubeMethodName(t.settings.tube_method)) : std::string("none"));
      variants.push_back(std::move(t));
    }
  }
  return variants;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const double rank = p / 100.0 * double(values.size() - 1);
  const size_t lo = size_t(std::floor(rank)), hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (rank - double(lo)) * (values[hi] - values[lo]);
}

double mean(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return values.empty() ? 0 : sum / double(values.size());
}

void runBench(const BenchOptions& o) {
  if (o.frames < 1 || o.frames > 100000) throw Error("--frames: expected 1 to 100000");
  if (!(std::fabs(o.step_deg) <= 360)) throw Error("--step: expected degrees in [-360, 360]");
  if (o.sample > o.frames) throw Error("--sample: expected at most --frames (" + std::to_string(o.frames) + ")");
  std::vector<Variant> variants = variantsFrom(o);
  nlohmann::json out;
  const FilterCriteria criteria = criteriaFrom(o.render.criteria).criteria;  // bad specs before any work
  uint32_t width = 0, height = 0;
  parseFrameSize(o.render.size, width, height);
  const std::optional<NiftiVolume> volume = readAnatomyOption(o.render);  // a bad file before any work
  bool need_points = false;
  for (const Variant& v : variants) need_points |= !drawsFiblets(v.settings.pipeline);

  auto context = createRenderContext(o.render);
  // A mesh variant on a device without VK_EXT_mesh_shader: refused before
  // any work, in one line.
  for (const Variant& v : variants)
    if (needsMeshShaders(v.settings.pipeline))
      if (const std::string why = fibletMeshRefusal(*context, v.settings.pipeline); !why.empty()) throw Error(why);
  // The tubes' buffers and the octrees, read by the renderers' tube and
  // SVO stages at each frame and released (by `tubes_owner`) before the
  // renderers and the device.
  GpuTubes tubes;
  GpuSvo svos[2];
  struct TubesOwner {
    const gpu::VulkanContext& context;
    GpuTubes& tubes;
    GpuSvo* svos;
    ~TubesOwner() {
      for (int k = 0; k < 2; ++k) destroySvo(context, svos[k]);
      destroyTubes(context, tubes);
    }
  };
  std::optional<TubesOwner> tubes_owner;
  bool svo_used[2] = {false, false};
  for (const Variant& v : variants)
    if (v.svo >= 0) svo_used[v.svo] = true;
  TubeCliOptions tube_options = o.tubes;
  if (svo_used[0] || svo_used[1]) useSvoTubeDefaults(tube_options);
  if (o.voxel_mm != 0.0f && !(svo_used[0] || svo_used[1]))
    throw Error("--voxel: only with an svo-straight or svo-curved pipeline");
  if (!o.svo_lod_px.empty() && !(svo_used[0] || svo_used[1]))
    throw Error("--svo-lod-px: only with an svo-straight or svo-curved pipeline");
  if (!(o.voxel_mm >= 0.0f) || !std::isfinite(o.voxel_mm))
    throw Error("--voxel: expected a voxel size > 0 mm, got " + std::to_string(o.voxel_mm));
  SceneOptions scene_options;
  scene_options.path = o.render.input;
  scene_options.phantom_streamlines = o.render.phantom_streamlines;
  scene_options.upload_raw = need_points;
  scene_options.fiber_scalars = criteria.scalar_ranges;
  LoadedScene scene = loadScene(*context, scene_options);
  GpuScene gpu_scene = scene.gpuScene();
  for (Variant& v : variants) applyScalarColoring(*context, scene.fiblets, o.render, v.settings, gpu_scene);
  GpuAnatomy anatomy;
  if (volume) {
    std::vector<RenderSettings*> fitted;
    for (Variant& v : variants) fitted.push_back(&v.settings);
    applyAnatomy(*context, *volume, o.render, fitted, anatomy, gpu_scene);
  }
  // The criteria, evaluated once: each variant's frames read the kept bits
  // of its pipeline's input.
  const SceneFilter filter(*context, scene, criteria, o.render.dim_dropped, int(o.filter_evaluations));
  const SceneCuts cuts(*context, o.render);
  cuts.apply(gpu_scene);
  std::vector<GpuScene> variant_scenes(variants.size(), gpu_scene);
  for (size_t i = 0; i < variants.size(); ++i) filter.apply(variant_scenes[i], variants[i].settings.pipeline);
  TubeBuildStats tube_stats;
  if (tube_options.requested()) {
    std::vector<uint32_t> kept;
    if (filter.active()) kept = filter.keptFibers();
    const TubeModel model = loadTubeModel(o.render.input, o.render.phantom_streamlines, tube_options, &tube_stats,
                                          filter.active() ? &kept : nullptr);
    tubes = uploadTubes(*context, model);
    tubes_owner.emplace(*context, tubes, svos);  // in place: a moved-from temporary would free them
    for (int k = 0; k < 2; ++k) {
      if (!svo_used[k]) continue;
      SvoGpuBuildOptions build;
      build.progress = true;
      SvoGpuBuildStats svo_stats;
      const SvoGrid grid = chooseSvoGrid(model, o.voxel_mm, k == 1, svoMemoryLimit(*context, build));
      const SvoTree tree = buildSvoGpu(*context, model, tubes, grid, build, &svo_stats);
      svos[k] = uploadSvo(*context, tree);
      const std::string line = svoBuildSummary(model, tree, svo_stats);
      if (!o.json) std::printf("%s: %s\n", std::string(kSvoPipelineNames[k]).c_str(), line.c_str());
      out["svo"][std::string(kSvoPipelineNames[k])]["summary"] = line;
      out["svo"][std::string(kSvoPipelineNames[k])]["node_bytes"] = tree.nodeBytes();
      out["svo"][std::string(kSvoPipelineNames[k])]["decoration_bytes"] = tree.decorationBytes();
      out["svo"][std::string(kSvoPipelineNames[k])]["lod_bytes"] = tree.lodBytes();
      out["svo"][std::string(kSvoPipelineNames[k])]["leaves"] = tree.leaves;
      out["svo"][std::string(kSvoPipelineNames[k])]["leaves_over_4"] = tree.leaves_over_4;
      out["svo"][std::string(kSvoPipelineNames[k])]["build_s"] = svo_stats.voxelize_s + svo_stats.sort_s + svo_stats.tree_s;
    }
    out["tubes"]["fibers"] = tube_stats.tubes;
    out["tubes"]["nodes"] = tube_stats.nodes;
    out["tubes"]["input_points"] = tube_stats.input_points;
    out["tubes"]["segments"] = tubes.segment_count;
    // The tubes buffer of the seed's figure 3 (node and segment records);
    // the methods' own per-frame buffers are not counted.
    out["tubes"]["buffer_bytes"] = tubes.nodes.size + tubes.segments.size;
  }

  // One renderer per variant: two-phase culling keeps the previous frame's
  // visibility, which must be its own.
  std::vector<std::unique_ptr<FrameRenderer>> renderers;
  for (size_t i = 0; i < variants.size(); ++i)
    renderers.push_back(std::make_unique<FrameRenderer>(
        *context, width, height,
        variants[i].svo >= 0 ? withSvoStage(standardFrameStages(), &svos[variants[i].svo], &tubes,
                                            SvoTraceOptions{variants[i].svo_lod_px})
        : variants[i].tubes  ? withTubeStage(standardFrameStages(), &tubes)
                             : standardFrameStages()));
  // --count-missed: the unculled frame each culled compute variant is
  // compared with (the first compute variant's settings, culling off).
  // With LoD on, frustum culling with the same LoD instead: culling off
  // has no LoD, and the LoD's segments would count as misses. Frustum
  // culling keeps every fiblet in view, so it draws culling off's frame
  // (bit for bit without LoD: gpu_culling_test.cpp) with the variants' LoD.
  std::unique_ptr<FrameRenderer> reference;
  RenderSettings reference_settings;
  GpuScene reference_scene = gpu_scene;
  if (o.count_missed) {
    const auto compute = std::find_if(variants.begin(), variants.end(), [](const Variant& v) {
      return v.settings.pipeline == RenderPipeline::Compute;
    });
    if (compute == variants.end()) throw Error("--count-missed: no compute variant to count missed pixels of");
    reference_settings = compute->settings;
    reference_settings.culling = reference_settings.lod_pixels > 0 ? CullingMode::Frustum : CullingMode::None;
    filter.apply(reference_scene, RenderPipeline::Compute);
    reference = std::make_unique<FrameRenderer>(*context, width, height);
  }
  uint64_t reference_covered = 0;
  // A constant distance for the whole orbit: the farthest of the snug fits
  // at 12 azimuths, so the tractogram fills the frame without leaving it.
  double distance = o.distance;
  if (distance == 0) {
    for (int k = 0; k < 12; ++k) {
      const double az = 30.0 * k;
      auto make = [&](double f) { return orbitCamera(scene.bounds, az, o.elevation_deg, width, height, f); };
      const Camera snug = snugCamera(scene.sample, make), sphere = make(1.0);
      auto dist = [](const Camera& c) {
        return std::hypot(c.eye[0] - c.target[0], c.eye[1] - c.target[1], c.eye[2] - c.target[2]);
      };
      distance = std::max(distance, dist(snug) / dist(sphere));
    }
  }
  out["distance_factor"] = distance;
  const std::vector<OrbitFrame> frames = orbitFrames(o);
  const uint32_t measured = o.sample == 0 ? o.frames : o.sample;
  for (const OrbitFrame& frame : frames) {
    const Camera camera = withAnatomyInView(
        orbitCamera(scene.bounds, frame.azimuth_deg, o.elevation_deg, width, height, distance), anatomy);
    for (size_t i = 0; i < variants.size(); ++i) {
      Variant& v = variants[i];
      const auto t0 = std::chrono::steady_clock::now();
      const FrameStats stats = renderers[i]->render(camera, v.settings, variant_scenes[i]);
      const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      if (!frame.measured) continue;
      v.gpu_ms.push_back(stats.gpu_ms);
      v.wall_ms.push_back(wall);
      const double total_fiblets = double(std::max<uint64_t>(stats.fiblets_total, 1));
      v.drawn_fraction.push_back(double(stats.fiblets_drawn) / total_fiblets);
      v.lod_fraction.push_back(double(stats.fiblets_lod) / total_fiblets);
      // Segments drawn: every segment for the baselines; for fiblets the
      // drawn fraction of the dataset's segments (fiblets hold ~N - 1 each)
      // plus one per LoD fiblet.
      v.segments_drawn_sum +=
          drawsFiblets(v.settings.pipeline)
              ? uint64_t(double(scene.segments) * double(stats.fiblets_drawn) / total_fiblets) + stats.fiblets_lod
              : scene.segments;
      double tube_ms = 0;
      for (const PassTiming& p : stats.passes) {
        if (isTubePass(p.name) || p.name == "svo trace") tube_ms += p.ms;
        if (!v.pass_ms_sum.count(p.name)) v.pass_order.push_back(p.name);
        v.pass_ms_sum[p.name] += p.ms;
      }
      if (v.tubes || v.svo >= 0) v.tube_ms.push_back(tube_ms);
      v.tube_method_bytes = std::max(v.tube_method_bytes, stats.tube_method_bytes);
    }
    // The reference after the variants: an occlusion variant's first frame
    // computes the datasets' exact fiblet spheres, which the frustum test
    // and LoD then use too (dataset.h); drawn before, the reference's
    // first frame would choose its LoD on the looser record bounds.
    if (reference && frame.measured) {
      reference->render(camera, reference_settings, reference_scene);
      const std::vector<uint64_t> reference_keys = downloadVisibility(*context, reference->targets());
      for (uint64_t key : reference_keys) reference_covered += key != ~uint64_t(0);
      for (size_t i = 0; i < variants.size(); ++i) {
        const RenderSettings& s = variants[i].settings;
        if (s.pipeline == RenderPipeline::Compute &&
            (s.culling == CullingMode::TwoPhase || s.culling == CullingMode::Coverage))
          countMissed(reference_keys, downloadVisibility(*context, renderers[i]->targets()), variants[i]);
      }
    }
  }
  checkValidation(*context, o.render);
  if (o.count_missed) {
    out["reference_covered_pixels"] = reference_covered;  // summed over the measured frames
    out["missed_reference"] = "compute/" + std::string(cullingModeName(reference_settings.culling));
  }

  out["input"] = scene.name;
  out["device"] = context->info().name;
  out["driver"] = context->info().driver_name + " " + context->info().driver_info;
  out["size"] = {width, height};
  out["frames"] = measured;
  if (o.sample != 0) out["sampled_from_frames"] = o.frames;
  out["step_deg"] = o.step_deg;
  out["streamlines"] = scene.streamlines;
  out["segments"] = scene.segments;
  out["fiblets"] = scene.fiblets.block().fiblet_count;
  if (filter.active()) {
    out["filter"]["kept"] = filter.kept();
    out["filter"]["gpu_ms"] = filter.gpuMilliseconds();  // the median of the evaluations
    out["filter"]["gpu_ms_each"] = filter.gpuMillisecondsEach();
    if (scene.has_raw) out["filter"]["raw_gpu_ms"] = filter.rawGpuMilliseconds();
  }
  // Ratios compare GPU time, except on a CPU device (lavapipe): there the
  // timestamps around the passes of a large dataset (34 M segments, 2-D
  // grids of 82 k and more workgroups) were seen to read close to zero
  // while the frame took seconds (cause not found; a 20 M-segment dataset
  // with 1-D grids timed right), so wall time (submit to fence, one frame
  // per submission, the CPU doing all the work) is the figure.
  const bool cpu_device = context->info().type == VK_PHYSICAL_DEVICE_TYPE_CPU;
  auto ratioTime = [&](const Variant& v) { return percentile(cpu_device ? v.wall_ms : v.gpu_ms, 50); };
  const double base_median = ratioTime(variants.front());
  out["ratio_basis"] = cpu_device ? "median wall ms (CPU device)" : "median GPU ms";
  if (!o.json) {
    std::printf("%s: %llu streamlines, %llu segments, %u fiblets; %u frames at %.2f deg/frame", scene.name.c_str(),
                static_cast<unsigned long long>(scene.streamlines), static_cast<unsigned long long>(scene.segments),
                scene.fiblets.block().fiblet_count, measured, o.step_deg);
    if (o.sample != 0) std::printf(" (sampled from an orbit of %u)", o.frames);
    std::printf(", %ux%u, %s\n", width, height, context->info().name.c_str());
    if (o.tubes.requested())
      std::printf("tubes: %llu fibers, %llu nodes (of %llu points), %u segments, tubes buffer %.2f MiB\n",
                  static_cast<unsigned long long>(tube_stats.tubes), static_cast<unsigned long long>(tube_stats.nodes),
                  static_cast<unsigned long long>(tube_stats.input_points), tubes.segment_count,
                  double(tubes.nodes.size + tubes.segments.size) / double(1 << 20));
    if (cpu_device)
      std::printf("note: CPU device: ratios use wall time (per-pass timestamps of large dispatches are unreliable "
                  "on lavapipe)\n");
    std::printf("%-20s %10s %10s %10s %10s %9s %9s %14s\n", "pipeline", "mean ms", "median ms", "p95 ms", "wall ms",
                "drawn", "lod", "segments/ms");
  }
  for (Variant& v : variants) {
    const double median = percentile(v.gpu_ms, 50);
    const std::vector<double>& frame_ms = cpu_device ? v.wall_ms : v.gpu_ms;
    const double gpu_total = std::max(1e-9, mean(frame_ms) * double(frame_ms.size()));
    const double segments_per_ms = double(v.segments_drawn_sum) / gpu_total;
    nlohmann::json j;
    j["pipeline"] = v.label;
    j["mean_ms"] = mean(v.gpu_ms);
    j["median_ms"] = median;
    j["p95_ms"] = percentile(v.gpu_ms, 95);
    j["wall_mean_ms"] = mean(v.wall_ms);
    const bool fiblets = drawsFiblets(v.settings.pipeline);  // the baselines draw every segment
    if (fiblets) {
      j["fiblets_drawn_fraction"] = mean(v.drawn_fraction);
      j["fiblets_lod_fraction"] = mean(v.lod_fraction);
      j["fiblets_drawn_fraction_per_frame"] = v.drawn_fraction;
    }
    j["segments_drawn_per_ms"] = segments_per_ms;
    if (!v.tube_ms.empty()) {
      j["tube_method"] = v.svo >= 0 ? kSvoPipelineNames[v.svo] : tubeMethodName(v.settings.tube_method);
      if (v.svo >= 0) j["svo_lod_px"] = v.svo_lod_px;
      j["tube_mean_ms"] = mean(v.tube_ms);
      j["tube_median_ms"] = percentile(v.tube_ms, 50);
      j["tube_method_bytes"] = v.tube_method_bytes;
    }
    j["wall_median_ms"] = percentile(v.wall_ms, 50);
    j["median_ratio_to_first"] = base_median > 0 ? ratioTime(v) / base_median : 0.0;
    for (const std::string& name : v.pass_order) j["pass_mean_ms"][name] = v.pass_ms_sum[name] / double(measured);
    uint64_t missed_total = 0, missed_max = 0;
    for (uint64_t m : v.missed_pixels) {
      missed_total += m;
      missed_max = std::max(missed_max, m);
    }
    if (!v.missed_pixels.empty()) {
      j["missed_pixels"] = v.missed_pixels;
      j["missed_pixels_total"] = missed_total;
      j["missed_pixels_max"] = missed_max;
      uint64_t changed_total = 0;
      for (uint64_t c : v.changed_pixels) changed_total += c;
      j["changed_pixels"] = v.changed_pixels;
      j["changed_pixels_total"] = changed_total;
    }
    if (!o.json) {
      std::printf("%-20s %10.3f %10.3f %10.3f %10.3f", v.label.c_str(), mean(v.gpu_ms), median,
                  percentile(v.gpu_ms, 95), mean(v.wall_ms));
      if (fiblets) std::printf(" %8.1f%% %8.1f%%", 100 * mean(v.drawn_fraction), 100 * mean(v.lod_fraction));
      else std::printf(" %9s %9s", "-", "-");
      std::printf(" %14.0f", segments_per_ms);
      if (variants.size() > 1) std::printf("   x%.2f of %s", base_median > 0 ? ratioTime(v) / base_median : 0.0,
                                           variants.front().label.c_str());
      if (!v.tube_ms.empty())
        std::printf("\n    tubes by %s: mean %.3f ms, median %.3f ms (their passes' GPU time), its buffers %.2f MiB",
                    std::string(v.svo >= 0 ? kSvoPipelineNames[v.svo] : tubeMethodName(v.settings.tube_method)).c_str(),
                    mean(v.tube_ms),
                    percentile(v.tube_ms, 50), double(v.tube_method_bytes) / double(1 << 20));
      std::printf("\n    passes:");
      for (const std::string& name : v.pass_order) std::printf(" %s %.3f", name.c_str(), v.pass_ms_sum[name] / double(measured));
      std::printf(" (mean ms)\n");
      if (!v.missed_pixels.empty())
        std::printf("    missed pixels (covered by compute/%s, not here): %llu in %zu frames, at most %llu in one; "
                    "%llu pixels changed\n",
                    std::string(cullingModeName(reference_settings.culling)).c_str(),
                    static_cast<unsigned long long>(missed_total), v.missed_pixels.size(),
                    static_cast<unsigned long long>(missed_max),
                    static_cast<unsigned long long>(
                        std::accumulate(v.changed_pixels.begin(), v.changed_pixels.end(), uint64_t(0))));
    }
    out["results"].push_back(j);
  }
  if (o.json) std::printf("%s\n", out.dump(2).c_str());
}

}  // namespace

void addBenchCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench", "Frame benchmark: the camera orbits the tractogram (fiblets paper protocol)");
  addRenderCliOptions(cmd, o->render);
  cmd->add_option("--compare", o->compare,
                  "Pipelines drawn on the same frames, e.g. compute/two-phase,compute/coverage,compute/none,lines,"
                  "raw-compute,geometry/frustum,tessellation/none,mesh/two-phase,mesh-serial/none (mesh: VK_EXT_mesh_shader),"
                  "svo-straight,svo-curved; ratios are to the first");
  addTubeCliOptions(cmd, o->tubes);
  cmd->add_option("--tube-compare", o->tube_compare,
                  "Tube methods drawn on the same frames, each with every --compare pipeline: none,compute,raycast,tess "
                  "(with --tubes; none: without tubes, the baseline of the tubes' wall time); the seed's protocol: --frames 500 --step 0.72 --size 800x600|1200x768, far "
                  "--distance 1, close --distance 0.3");
  cmd->add_option("--voxel", o->voxel_mm,
                  "Voxel size of the octree in mm for svo-straight and svo-curved (--pipeline or --compare; default: "
                  "from the tube radius and the step, coarser where the octree would not fit the device's memory)");
  cmd->add_option("--svo-lod-px", o->svo_lod_px,
                  std::string(kSvoLodHelp) + "; PX,PX,...: each svo variant once per value, on the same frames "
                  "[default 0]");
  cmd->add_option("--frames", o->frames, "Measured frames")->capture_default_str();
  cmd->add_option("--step", o->step_deg, "Orbit step per frame, degrees")->capture_default_str();
  cmd->add_option("--elevation", o->elevation_deg, "Orbit elevation, degrees")->capture_default_str();
  cmd->add_option("--distance", o->distance, "Camera distance factor (1: the bounding sphere fits; 0: as close as frames the tractogram all around)")->capture_default_str();
  cmd->add_option("--warmup", o->warmup, "Unmeasured frames first")->capture_default_str();
  cmd->add_option("--sample", o->sample,
                  "Measure N frames spread evenly over the orbit, each after the frame one step before it "
                  "(0: every frame)")
      ->capture_default_str();
  cmd->add_option("--filter-evaluations", o->filter_evaluations,
                  "Evaluate the --include/--exclude/length criteria on the fiblets N times, each re-testing every "
                  "criterion as a changed ROI does (JSON: filter.gpu_ms, their median, and filter.gpu_ms_each)")
      ->check(CLI::Range(1u, 1000u))
      ->capture_default_str();
  cmd->add_flag("--count-missed", o->count_missed,
                "Also draw each measured frame with culling off (frustum culling with the same LoD when LoD is on; "
                "untimed) and count the pixels each occlusion-culled compute variant misses (JSON: missed_pixels "
                "per frame, missed_pixels_total)");
  cmd->add_flag("--json", o->json, "Print the results as JSON");
  cmd->callback([o] { runBench(*o); });
}

}  // namespace fibscope
