#include "app/viewer/viewer_app.h"

#include <imgui.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <memory>
#include <optional>
#include <thread>
#include <type_traits>

#include "app/bundle_output.h"
#include "app/model_loader.h"
#include "app/open_input.h"
#include "app/viewer/adaptive_detail.h"
#include "app/viewer/viewer_bundling.h"
#include "app/viewer/dissection.h"
#include "app/viewer/imgui_layer.h"
#include "app/viewer/orbit_controller.h"
#include "app/viewer/presentation.h"
#include "app/viewer/recent_files.h"
#include "app/viewer/split_view.h"
#include "app/viewer/viewer_cuts.h"
#include "app/viewer/viewer_anatomy.h"
#include "app/viewer/viewer_dissection.h"
#include "app/viewer/viewer_input.h"
#include "app/viewer/viewer_script.h"
#include "app/viewer/viewer_selection.h"
#include "app/viewer/viewer_tubes.h"
#include "app/viewer/viewer_state.h"
#include "app/viewer/viewer_ui.h"
#include "app/viewer/viewer_window.h"
#include "codec/fbl_codec.h"
#include "codec/fbl_reader.h"
#include "core/error.h"
#include "gpu/submit.h"
#include "gpu/swapchain.h"
#include "gpu/vk_check.h"
#include "io/png_writer.h"
#include "phantom/phantom.h"
#include "render/colormap.h"
#include "render/gpu/dataset.h"
#include "render/gpu/fiblet_mesh_pass.h"
#include "render/gpu/frame_renderer.h"
#include "render/gpu/pick.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/scene_table.h"
#include "render/gpu/upscale_pass.h"
#include "select/fiber_filter.h"
#include "svo/gpu/gpu_distance_field.h"
#include "svo/gpu/gpu_svo.h"

namespace fibscope {
namespace {

using Clock = std::chrono::steady_clock;

// One model of the list: what the loader produced (kept whole: exporting
// selected fibers and the fiber lengths read its .fbl), its fiblets on the
// device and, once a baseline pipeline asked for them, its raw vertices.
struct ViewerModel {
  uint64_t id = 0;  // unique per load (the selection names models by it)
  std::shared_ptr<ModelData> data;  // shared with a tube build that reads its .fbl
  GpuDataset fiblets;
  GpuRawTractogram raw;
  bool has_raw = false;
  // The step its source file's header states (the length limits' margin,
  // as `fibscope filter` takes it), NaN when none.
  float step_size_mm = NAN;
};

// What the next frame draws: every visible model's fiblets in one scene
// (scene-global fiber ids, render/gpu/scene_table.h), or a baseline
// pipeline's raw vertices of the active model alone.
struct FrameScene {
  std::vector<int> models;  // the drawn models (indices into the list), in the scene's order
  GpuScene gpu;
  SceneLayout layout;        // of gpu.datasets: picks map fiber ids back through it
  RenderSettings settings;   // the state's, with a baseline not ready replaced by compute, and the dissection's cuts
  // The dissection draws the kept fibers as the selection (dropped ones
  // dimmed): gpu.selection_bits holds its bits, not the picked selection's.
  bool dissection_selects = false;
  bool empty() const { return models.empty(); }
};

// A reader that stops at the next chunk once `cancel` is set (a raw decode
// of a model closed meanwhile, or the viewer quitting).
class CancelOnFlag final : public TractogramReader {
 public:
  CancelOnFlag(std::unique_ptr<TractogramReader> inner, const std::atomic<bool>& cancel)
      : inner_(std::move(inner)), cancel_(cancel) {
    header_ = inner_->header();
  }
  bool read(Tractogram& chunk, size_t max_points) override {
    if (cancel_.load(std::memory_order_relaxed)) fail(header_.path.empty() ? "raw vertices" : header_.path, "cancelled");
    return inner_->read(chunk, max_points);
  }
  uint64_t bytesRead() const override { return inner_->bytesRead(); }

 private:
  std::unique_ptr<TractogramReader> inner_;
  const std::atomic<bool>& cancel_;
};

// The baselines' raw vertices of a loaded model, decoded on a thread of
// their own (CPU only; the upload stays on the main thread): the model's
// .fbl through openFbl, so fiber ids and points are the compressed file's
// (what `fibscope decompress` gives). A copy that lives only while mapped
// (unwritable cache) has no path to reopen: the source is read instead.
struct RawDecode {
  const ViewerModel* model = nullptr;
  std::shared_ptr<std::atomic<bool>> cancel;
  std::future<Tractogram> points;
};

Tractogram decodeRawVertices(const std::string& fbl_path, const std::string& source_path, uint64_t phantom_streamlines,
                             const std::atomic<bool>& cancel) {
  std::unique_ptr<TractogramReader> inner;
  if (!fbl_path.empty()) {
    inner = openFbl(fbl_path);
  } else if (!source_path.empty()) {
    inner = openInput(source_path);
  } else {
    PhantomOptions phantom;
    phantom.streamlines = phantom_streamlines;
    inner = openPhantom(phantom);
  }
  CancelOnFlag reader(std::move(inner), cancel);
  return readAllStreamlines(reader);
}

class ViewerApp {
 public:
  explicit ViewerApp(const ViewerOptions& options);
  ~ViewerApp();
  ViewerApp(const ViewerApp&) = delete;
  ViewerApp& operator=(const ViewerApp&) = delete;

  void run();

 private:
  // Everything after the context: swapchain, presentation, UI, renderer,
  // the frame's command buffer and fence, the models.
  void createFrameObjects();
  void release();
  void apply(const ViewerAction& action);
  // Queues a load on the worker; `at_start`: a command-line file (an error
  // then ends the run).
  void openModel(const std::string& path, bool at_start = false);
  // Finished loads -> uploaded models (main thread, no frame in flight),
  // errors -> status and the panel; the running job's progress -> state_.
  void pollLoads();
  // Shows the anatomical image read on its thread once it is (ViewerAnatomy::poll).
  void pollAnatomy();
  void anatomyShown(const std::string& path);
  void addModel(LoadEvent& event);
  void closeModel(int model);
  // The camera on the union of the visible models (every model when none
  // is visible): framed for the first, refitted after; and the scalar range
  // on their fiber lengths.
  void frameVisibleModels();
  // frameVisibleModels when a model was added or closed since the last.
  void frameIfModelsChanged();
  // The orbit controller's camera, its near and far widened to the visible
  // models and the anatomy (show and hide keep the framing: a model shown
  // later may reach beyond the box the camera was framed on).
  Camera viewCamera(uint32_t width, uint32_t height) const;
  void fitScalarRange();
  // What the next frame draws (between frames: the scene's fiber lengths
  // may be copied, the dissection's filter evaluated; `filter_now`: without
  // waiting for a drag to settle).
  FrameScene currentScene(bool filter_now = false);
  FrameScene sceneToDraw();
  // The split view (split_view.h): on, with both of its models loaded.
  bool splitActive() const;
  // One model alone, for a half of the split view: the compute pipeline
  // (the baselines draw one raw tractogram), the dissection's cuts, not its
  // filter (its kept bits are numbered for the whole scene).
  FrameScene modelScene(int model);
  // Both halves recorded and composed into `out` (width x height RGBA8).
  void recordSplit(VkCommandBuffer cmd, const Camera& camera, const gpu::Buffer& out);
  // The dissection (viewer_dissection.h) on `scene`: its cuts in the
  // settings, its kept bits in the GpuScene.
  void dissect(FrameScene& scene, bool now);
  void applyDissection(const ViewerAction& action);
  void pollExport();
  // Bundling (viewer_bundling.h): the job's progress -> state_, its result
  // opened through the loader; the copy once loaded shown and active.
  void startBundle(const BundleParams& params);
  void pollBundling();
  void bundledModelAdded();
  void saveModel(const SaveModelAction& save);
  // The fiber drawn at window pixel (x, y) of the last frame (no hit when
  // none is drawn there or no frame is).
  PickResult pickDrawn(double x, double y);
  void placeRoiAt(double x, double y);
  uint64_t activeModelId() const;
  void ensureRawFor(int model);
  void pollRawDecode();
  void cancelRawDecode();
  void resizeTo(uint32_t width, uint32_t height);
  // Waits for the frame in flight and records its statistics.
  void finishFrame();
  bool drawFrame(uint32_t width, uint32_t height, double dt);
  void recordFrame(VkCommandBuffer cmd, uint32_t width, uint32_t height, const Camera& camera,
                   const FrameScene& scene);
  void takeScreenshot(const ScreenshotAction& shot);
  // With --orbit: frames, mean / median / p95 wall time per frame, to stderr.
  void printFrameSummary(std::vector<double> frame_ms) const;
  // Picking and the selection (viewer_selection.h), between frames.
  void syncSelection(const FrameScene& scene);
  void syncSelection() { syncSelection(currentScene()); }
  // The tubes panel's fibers of `scene` as tubes (viewer_tubes.h), between frames.
  void syncTubes(const FrameScene& scene);
  // The frame stages of every renderer: the standard ones, the spline
  // tubes, the SVO streamtubes and the tubes' distance field (each runs
  // only while ViewerTubes holds its buffers).
  FrameStageList frameStages() const {
    return withDistanceFieldStage(
        withSvoStage(withTubeStage(standardFrameStages(), tubes_->gpu()), tubes_->svo(), tubes_->svoSegments(),
                     SvoTraceOptions{0.0f, 0, &state_.tubes.svo_lod_px}),
        tubes_->field());
  }
  void pickAt(const PickAction& pick);
  GpuScene withSelection(const FrameScene& scene) const;
  // An anatomy action (viewer_anatomy.h), between frames; `at_start`: the
  // command line's (an error then ends the run).
  void loadAnatomy(const std::string& path, bool at_start = false);
  std::string freshScreenshotPath();

  ViewerOptions options_;
  // Destroyed last: the context's surface must go before the window.
  std::unique_ptr<ViewerWindow> window_;
  std::unique_ptr<gpu::VulkanContext> context_;
  gpu::Swapchain swapchain_;
  bool swapchain_stale_ = false;
  Presentation presentation_;
  std::unique_ptr<ImGuiLayer> imgui_;
  std::unique_ptr<FrameRenderer> renderer_;
  std::unique_ptr<FrameRenderer> shot_renderer_;  // scene-only screenshots at a chosen size
  // Coarse frames (adaptive detail) at half resolution, upscaled into
  // renderer_'s colour buffer; both made at the first coarse frame.
  std::unique_ptr<FrameRenderer> coarse_renderer_;
  std::unique_ptr<FrameRenderer> split_renderers_[2];  // the split view's halves (left, right)
  double split_reported_factor_ = 0;                    // the halves' distance factor last printed
  bool split_recorded_ = false;                        // the frame in flight is a split one
  UpscalePass upscale_;
  bool upscale_ready_ = false;
  // The renderer that recorded the frame last submitted (its statistics and
  // G-buffer; null for a background-only frame).
  FrameRenderer* recorded_renderer_ = nullptr;
  std::vector<std::unique_ptr<ViewerModel>> scenes_;  // index-aligned with state_.models
  uint64_t next_model_id_ = 1;
  std::vector<uint64_t> framed_ids_;  // the models loaded when the camera was last framed
  std::vector<uint64_t> scalar_range_ids_;  // the visible models the scalar range was fitted to
  std::unique_ptr<ViewerSelection> selection_;
  // The spline tubes (viewer_tubes.h): made before the renderers, whose
  // tube stage reads its buffers at every frame, and released after them.
  std::unique_ptr<ViewerTubes> tubes_;
  std::unique_ptr<GpuSceneFiberLengths> scene_lengths_;  // the scalar colour mode's per-fiber values
  std::unique_ptr<ViewerDissection> dissection_;
  std::unique_ptr<ViewerCuts> cuts_;  // the dissection's cut meshes on the GPU
  bool dissection_opened_ = false;  // the panel was opened for the dissection's first ROI or plane
  ViewerAnatomy anatomy_;  // the anatomical image shown as slices
  // The scene the G-buffer shows (the last frame drawn; no models after a
  // resize or a frame without a model): picks map its fiber ids to the
  // model ids here.
  SceneLayout drawn_layout_;
  std::vector<uint64_t> drawn_ids_;
  // Loading: one worker (model_loader.h); the jobs named on the command
  // line not finished yet (frames and the script count once they are).
  std::unique_ptr<ModelLoader> loader_;
  std::vector<uint64_t> startup_jobs_;
  std::vector<std::pair<uint64_t, uint64_t>> job_first_frame_;  // job id, frames_drawn_ when requested
  std::optional<RawDecode> raw_decode_;
  std::unique_ptr<ViewerBundling> bundling_;
  uint64_t bundle_source_id_ = 0;   // the model being bundled (ViewerModel::id)
  uint64_t bundle_load_job_ = 0;    // the loader's job opening the bundled copy (0: none)
  uint64_t bundle_first_frame_ = 0;  // frames_drawn_ when the job started
  uint64_t bundle_frames_ = 0;       // frames drawn while the job ran
  std::optional<ViewerBundleResult> bundle_result_;
  std::vector<std::pair<uint64_t, std::string>> bundled_exact_;  // a bundled model's id, its exact .tck
  std::string recent_files_path_;
  uint64_t frames_drawn_ = 0;

  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool in_flight_ = false;
  // Adaptive detail (recordFrame, adaptive_detail.h).
  bool frame_coarse_ = false;      // the frame being recorded
  bool submitted_coarse_ = false;  // the frame in flight
  Clock::time_point submitted_at_;
  double last_full_frame_ms_ = 0;
  double last_coarse_frame_ms_ = 0;  // submission to completion of the last coarse frame
  unsigned coarse_divisor_ = 2;      // a coarse frame's size: the window's / this (coarseDivisor)
  Camera last_camera_;  // of the last frame recorded
  Clock::time_point frame_start_;
  double last_frame_ms_ = 0;

  ViewerState state_;
  OrbitController controller_;
  InputMapper input_;
  ScriptRunner script_;
  bool quit_ = false;
  // A screenshot "as shown" taken once this frame is on the image.
  std::optional<std::string> pending_shot_;
  int screenshot_counter_ = 0;
};

ViewerApp::ViewerApp(const ViewerOptions& options) : options_(options) {
  // The script first: a malformed one is reported before a window opens.
  if (!options_.script.empty()) script_ = ScriptRunner(loadScript(options_.script));
  state_.settings = options_.settings;
  // The dissection owns the clip planes: the command line's (--clip-plane,
  // a --roi-set's) become its planes, before the ROIs' set's own.
  state_.dissection.set = options_.dissection;
  std::vector<RoiClipPlane> planes = clipPlanesFromSettings(state_.settings.clip_planes);
  planes.insert(planes.end(), options_.dissection.clip_planes.begin(), options_.dissection.clip_planes.end());
  state_.dissection.set.clip_planes = std::move(planes);
  state_.settings.clip_planes.clear();
  state_.dissection.dim_dropped = options_.dim_dropped;

  if (!options_.offscreen) {
    std::string why_not;
    window_ = ViewerWindow::open(options_.width, options_.height, "fibscope", why_not);
    if (!window_) {
      std::fprintf(stderr, "fibscope view: %s; rendering offscreen\n", why_not.c_str());
      if (options_.frames == 0 && options_.script.empty()) options_.frames = 1;
    }
  } else if (options_.frames == 0 && options_.script.empty()) {
    options_.frames = 1;  // offscreen with nothing to stop it: one frame
  }

  gpu::ContextOptions context_options;
  context_options.instance.validation = options_.validate;
  context_options.device_name = options_.device;
  if (window_) {
    context_options.instance.extensions = ViewerWindow::requiredInstanceExtensions();
    ViewerWindow* window = window_.get();
    context_options.surface_factory = [window](VkInstance instance) { return window->createSurface(instance); };
  }
  context_ = std::make_unique<gpu::VulkanContext>(context_options);
  try {
    createFrameObjects();
  } catch (...) {
    release();
    throw;
  }
}

void ViewerApp::createFrameObjects() {
  uint32_t width = options_.width, height = options_.height;
  if (window_) {
    window_->framebufferSize(width, height);
    if (width == 0 || height == 0) width = options_.width, height = options_.height;
    swapchain_ = gpu::createSwapchain(*context_, width, height, gpu::SwapchainOptions{options_.vsync});
    std::fprintf(stderr, "fibscope view: window %ux%u, present mode %s\n", swapchain_.extent.width,
                 swapchain_.extent.height, gpu::presentModeName(swapchain_.present_mode));
  }
  presentation_ = createPresentation(*context_, width, height);
  imgui_ = std::make_unique<ImGuiLayer>(*context_, presentation_.render_pass, window_ ? window_->handle() : nullptr);
  tubes_ = std::make_unique<ViewerTubes>(
      *context_, options_.device, options_.validate ? context_->instance().sharedLog() : std::shared_ptr<gpu::DebugLog>{});
  renderer_ = std::make_unique<FrameRenderer>(*context_, width, height, frameStages());
  selection_ = std::make_unique<ViewerSelection>(*context_);
  scene_lengths_ = std::make_unique<GpuSceneFiberLengths>(*context_);
  dissection_ = std::make_unique<ViewerDissection>(*context_);
  cuts_ = std::make_unique<ViewerCuts>(*context_);

  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = context_->commandPool();
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  gpu::throwIfFailed(vkAllocateCommandBuffers(context_->device(), &alloc, &cmd_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  gpu::throwIfFailed(vkCreateFence(context_->device(), &fence_info, nullptr, &fence_), "vkCreateFence");

  controller_.setViewport(width, height);
  recent_files_path_ = defaultRecentFilesPath();
  state_.recent_files = loadRecentFiles(recent_files_path_);
  ModelLoaderOptions loader_options;
  loader_options.phantom_streamlines = options_.phantom_streamlines;
  loader_ = std::make_unique<ModelLoader>(loader_options);
  bundling_ = std::make_unique<ViewerBundling>(
      options_.device, options_.validate ? context_->instance().sharedLog() : std::shared_ptr<gpu::DebugLog>{});
  // Loaded on the worker while frames are drawn; a file that cannot be
  // read shows its error (pollLoads; offscreen, one named on the command
  // line ends the run).
  if (options_.files.empty()) openModel("", true);
  for (const std::string& file : options_.files) openModel(file, true);
  if (!options_.anatomy.empty()) loadAnatomy(options_.anatomy, true);
}

void ViewerApp::loadAnatomy(const std::string& path, bool at_start) {
  finishFrame();  // the frame in flight may read the volume replaced
  try {
    if (path.empty()) {
      anatomy_.unload(state_);
      state_.status = "anatomy closed";
      return;
    }
    if (!at_start) {
      // Read on a thread of its own while frames go on; pollAnatomy shows it.
      anatomy_.startLoad(path);
      state_.status = "reading anatomy " + path + " ...";
      return;
    }
    // The command line's: read before the first frame, an error ends the
    // run; its slice positions and range stay for its image.
    const auto given = [&](std::string_view name) { return options_.given_settings.count(name) > 0; };
    anatomy_.load(*context_, path, state_, given);
    anatomyShown(path);
  } catch (const Error& e) {
    if (at_start) throw;
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

ViewerApp::~ViewerApp() { release(); }

void ViewerApp::release() {
  if (!context_) return;
  bundling_.reset();  // cancels a bundling job at its next iteration and joins its worker
  loader_.reset();  // cancels the running job and joins the worker
  cancelRawDecode();
  vkDeviceWaitIdle(context_->device());
  imgui_.reset();
  shot_renderer_.reset();
  coarse_renderer_.reset();
  for (auto& r : split_renderers_) r.reset();
  recorded_renderer_ = nullptr;
  if (upscale_ready_) destroyUpscalePass(*context_, upscale_);
  upscale_ready_ = false;
  renderer_.reset();
  tubes_.reset();  // after every renderer (their tube stage reads its buffers)
  selection_.reset();
  scene_lengths_.reset();
  dissection_.reset();  // cancels an export
  cuts_.reset();
  anatomy_.unload(state_);
  scenes_.clear();
  destroyPresentation(*context_, presentation_);
  if (swapchain_.swapchain != VK_NULL_HANDLE) gpu::destroySwapchain(*context_, swapchain_);
  if (fence_ != VK_NULL_HANDLE) vkDestroyFence(context_->device(), fence_, nullptr);
  if (cmd_ != VK_NULL_HANDLE) vkFreeCommandBuffers(context_->device(), context_->commandPool(), 1, &cmd_);
  fence_ = VK_NULL_HANDLE;
  cmd_ = VK_NULL_HANDLE;
  context_.reset();
}

void ViewerApp::openModel(const std::string& path, bool at_start) {
  const uint64_t id = loader_->request(path);
  if (at_start) startup_jobs_.push_back(id);
  job_first_frame_.emplace_back(id, frames_drawn_);
}

void ViewerApp::anatomyShown(const std::string& path) {
  state_.anatomy_path = path;
  state_.status = "anatomy " + path;
  std::fprintf(stderr, "fibscope view: anatomy %s: %d x %d x %d voxels\n", path.c_str(), state_.anatomy.dims[0],
               state_.anatomy.dims[1], state_.anatomy.dims[2]);
}

void ViewerApp::pollAnatomy() {
  const std::string path = anatomy_.loadingPath();
  try {
    if (anatomy_.poll(*context_, state_)) anatomyShown(path);
  } catch (const Error& e) {
    // The volume shown stays.
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

void ViewerApp::pollLoads() {
  for (LoadEvent& event : loader_->poll()) {
    const auto at_start = std::find(startup_jobs_.begin(), startup_jobs_.end(), event.id);
    const bool startup = at_start != startup_jobs_.end();
    if (startup) startup_jobs_.erase(at_start);
    if (event.cancelled) continue;
    if (event.ok()) {
      try {
        addModel(event);
        if (event.id == bundle_load_job_) bundledModelAdded();
        continue;
      } catch (const Error& e) {
        event.error = e.what();  // the upload failed (e.g. it does not fit on the device)
      }
    }
    // A command-line file that cannot be read: in a window it is shown as
    // one opened from the panel is (status line, the models panel's list of
    // failures) and the viewer goes on; without a window nobody would see
    // it, so the run ends with its one-line error (exit 2), as `render`'s.
    if (event.id == bundle_load_job_) {
      bundle_load_job_ = 0;
      state_.bundling.running = false;
      state_.bundling.message = event.error;
    }
    if (startup && !window_) throw Error(event.error);
    state_.status = event.error;
    state_.load_failures.push_back(LoadFailure{event.path, event.error});
    std::fprintf(stderr, "fibscope view: %s\n", event.error.c_str());
  }
  // Framed now, not by the next drawFrame: this frame's script steps (after
  // a wait-loaded or wait-bundle) and input see the new framing, and the
  // framing sees the bundled copy's source hidden.
  frameIfModelsChanged();
  state_.loading.clear();
  const size_t pending = loader_->pending();
  for (const LoadProgress& p : loader_->progress()) {
    LoadingInfo info;
    info.path = p.path;
    info.label = p.snapshot.label;
    info.unit = p.snapshot.unit;
    info.done = p.snapshot.done;
    info.total = p.snapshot.total;
    info.rate = p.snapshot.rate;
    info.eta_seconds = p.snapshot.eta_seconds;
    info.elapsed_seconds = p.snapshot.elapsed_seconds;
    info.queued = pending > 0 ? pending - 1 : 0;
    state_.loading.push_back(std::move(info));
  }
  if (state_.loading.empty() && pending > 0) {  // queued, not started yet
    LoadingInfo info;
    info.label = "queued";
    info.queued = pending - 1;
    state_.loading.push_back(std::move(info));
  }
}

void ViewerApp::addModel(LoadEvent& event) {
  ModelData& data = *event.model;
  for (const std::string& warning : data.warnings)
    std::fprintf(stderr, "fibscope view: warning: %s\n", warning.c_str());
  finishFrame();  // the upload must not race the frame in flight
  const auto start = Clock::now();
  auto model = std::make_unique<ViewerModel>();
  model->id = next_model_id_++;
  model->fiblets = GpuDataset::upload(*context_, data.fbl);
  if (const FblSection* source = data.fbl.find(kFblSectionSource)) {
    try {
      const auto text = data.fbl.data(*source);
      const std::string_view json(reinterpret_cast<const char*>(text.data()), text.size());
      model->step_size_mm = headerStepSize(headerFromFblSource(json, data.fbl.path()));
    } catch (const Error&) {
      // No margin then (the opening checked the section already).
    }
  }
  const double upload_seconds = std::chrono::duration<double>(Clock::now() - start).count();

  ModelInfo info;
  info.name = data.name;
  info.path = data.source_path;
  info.streamlines = data.streamlines;
  info.points = data.points;
  info.segments = data.segments;
  info.fiblets = data.fiblets;
  info.step_mm = data.step_mm;
  info.input_bytes = data.input_bytes;
  info.fbl_bytes = data.fbl_bytes;
  info.from_cache = data.from_cache;
  info.compress_seconds = data.compress_seconds;
  info.mean_error_um = data.mean_error_um;
  info.max_error_um = data.max_error_um;
  info.load_seconds = data.seconds + upload_seconds;
  model->data = std::move(event.model);
  state_.models.push_back(info);
  scenes_.push_back(std::move(model));
  state_.active_model = int(state_.models.size()) - 1;  // framed at the end of pollLoads
  scene_lengths_->invalidate();

  uint64_t frames_meanwhile = 0;
  for (auto it = job_first_frame_.begin(); it != job_first_frame_.end(); ++it)
    if (it->first == event.id) {
      frames_meanwhile = frames_drawn_ - it->second;
      job_first_frame_.erase(it);
      break;
    }
  // On stderr too, so that scripts and tests see whether compression ran.
  char line[512];
  std::snprintf(line, sizeof(line), "opened %s %s in %.2f s (%.2f s in all, %llu frames drawn meanwhile)",
                info.name.c_str(), info.from_cache ? "from cache" : "compressed",
                info.from_cache ? info.load_seconds : info.compress_seconds, info.load_seconds,
                static_cast<unsigned long long>(frames_meanwhile));
  state_.status = line;
  std::fprintf(stderr, "fibscope view: %s\n", line);

  if (!info.path.empty()) {
    state_.recent_files = addRecentFile(std::move(state_.recent_files), info.path);
    const std::string why_not = saveRecentFiles(recent_files_path_, state_.recent_files);
    if (!why_not.empty() && !recent_files_path_.empty())
      std::fprintf(stderr, "fibscope view: warning: recent files not saved: %s\n", why_not.c_str());
  }
}

void ViewerApp::closeModel(int model) {
  if (model < 0 || model >= int(scenes_.size())) return;
  finishFrame();  // the frame in flight may read the model's buffers
  if (raw_decode_ && raw_decode_->model == scenes_[size_t(model)].get()) cancelRawDecode();
  scenes_.erase(scenes_.begin() + model);
  state_.models.erase(state_.models.begin() + model);
  auto shift = [&](int& index) {
    if (index == model) index = -1;
    else if (index > model) --index;
  };
  const bool was_active = state_.active_model == model;
  shift(state_.active_model);
  shift(state_.bundling.source_model);
  shift(state_.bundling.bundled_model);
  shift(state_.split.left);
  shift(state_.split.right);
  if (state_.split.left < 0 || state_.split.right < 0) state_.split = {};
  scene_lengths_->invalidate();
  drawn_layout_ = {};  // the G-buffer may show the closed model: no picks until the next frame
  drawn_ids_.clear();
  // The next model takes the closed one's place (framed by the next drawFrame).
  if (was_active && !state_.models.empty()) state_.active_model = std::min(model, int(state_.models.size()) - 1);
}

void ViewerApp::frameIfModelsChanged() {
  std::vector<uint64_t> ids;
  for (const auto& m : scenes_) ids.push_back(m->id);
  if (ids != framed_ids_) frameVisibleModels();
}

void ViewerApp::frameVisibleModels() {
  // The first model frames the default view; later additions and closes
  // keep the user's (OrbitController::refit).
  const bool keep_view = !framed_ids_.empty();
  framed_ids_.clear();
  for (const auto& m : scenes_) framed_ids_.push_back(m->id);
  bool any_visible = false;
  for (const ModelInfo& m : state_.models) any_visible |= m.visible;
  Bounds bounds;
  std::vector<Vec3d> sample;
  bool first = true;
  for (size_t i = 0; i < scenes_.size(); ++i) {
    if (any_visible && !state_.models[i].visible) continue;
    const ModelData& data = *scenes_[i]->data;
    bounds = first ? data.bounds : boundsUnion(bounds, data.bounds);
    first = false;
    sample.insert(sample.end(), data.sample.begin(), data.sample.end());
  }
  if (!first) {
    if (keep_view) controller_.refit(bounds, sample);
    else controller_.frame(bounds, sample);
    state_.scene_bounds = bounds;
  }
}

Camera ViewerApp::viewCamera(uint32_t width, uint32_t height) const {
  std::vector<Vec3d> corners;
  for (size_t i = 0; i < scenes_.size(); ++i)
    if (state_.models[i].visible)
      for (const Vec3d& c : boundsCorners(scenes_[i]->data->bounds)) corners.push_back(c);
  return anatomy_.inView(enclosingDepthRange(controller_.camera(width, height), corners));
}

void ViewerApp::fitScalarRange() {
  // The scalar colour mode's range follows the models shown: their fibers'
  // lengths (one colormap over the scene, so models compare).
  scalar_range_ids_.clear();
  state_.scalar_data_min = 1, state_.scalar_data_max = 0;
  for (size_t i = 0; i < scenes_.size(); ++i) {
    if (!state_.models[i].visible) continue;
    scalar_range_ids_.push_back(scenes_[i]->id);
    const ModelData& data = *scenes_[i]->data;
    if (const FblSection* section = data.fbl.find(kFblSectionFiberLength)) {
      try {
        float lo = 1, hi = 0;
        finiteRange(data.fbl.array<float>(*section), lo, hi);
        if (lo > hi) continue;
        const bool none_yet = state_.scalar_data_min > state_.scalar_data_max;
        state_.scalar_data_min = none_yet ? lo : std::min(state_.scalar_data_min, lo);
        state_.scalar_data_max = none_yet ? hi : std::max(state_.scalar_data_max, hi);
      } catch (const Error& e) {
        state_.status = e.what();
      }
    }
  }
  if (!options_.keep_scalar_range && state_.scalar_data_min <= state_.scalar_data_max) {
    state_.settings.scalar_min = state_.scalar_data_min;
    state_.settings.scalar_max = state_.scalar_data_max;
  }
}

uint64_t ViewerApp::activeModelId() const {
  const int m = state_.active_model;
  return m >= 0 && m < int(scenes_.size()) ? scenes_[size_t(m)]->id : 0;
}

FrameScene ViewerApp::currentScene(bool filter_now) {
  FrameScene scene = sceneToDraw();
  dissect(scene, filter_now);
  return scene;
}

void ViewerApp::dissect(FrameScene& scene, bool now) {
  addDissectionCuts(state_.dissection.set, scene.settings);
  const bool baseline = !drawsFiblets(scene.settings.pipeline) && scene.gpu.raw != nullptr;
  DissectionScene d;
  d.layout = &scene.layout;
  if (!scene.models.empty()) {
    const ViewerModel& first = *scenes_[size_t(scene.models.front())];
    d.step_size_mm = first.step_size_mm;  // the models of one scene rarely differ; the first one's margin
    if (baseline) {
      d.raw = scene.gpu.raw;
      d.raw_lengths = first.fiblets.fiberLength().address;  // the raw vertices are its fibers, in order
    }
    // The per-fiber values of the scalar ranges: each drawn model's .fbl.
    for (const int m : scene.models) {
      const ViewerModel& model = *scenes_[size_t(m)];
      d.files.push_back(model.data ? &model.data->fbl : nullptr);
      if (baseline) break;
    }
  }
  try {
    finishFrame();  // an update rewrites the bits the frame in flight reads (and a sync frees meshes it may draw)
    cuts_->sync(state_.dissection);
    cuts_->apply(state_.dissection.set, scene.gpu);
    dissection_->evaluate(state_.dissection, d, now);
  } catch (const Error& e) {
    state_.status = e.what();
  }
  scene.dissection_selects = dissection_->apply(state_.dissection, scene.gpu, baseline);
}

FrameScene ViewerApp::sceneToDraw() {
  FrameScene scene;
  if (needsMeshShaders(state_.settings.pipeline))
    if (const std::string why = fibletMeshRefusal(*context_, state_.settings.pipeline); !why.empty()) {
      // Refused (no VK_EXT_mesh_shader): said in the status line, and the
      // choice goes back to compute rather than failing every frame.
      state_.status = why;
      state_.settings.pipeline = RenderPipeline::Compute;
    }
  scene.settings = state_.settings;
  state_.baseline_draws_active_only = false;
  const int active = state_.active_model;
  const bool active_shown = active >= 0 && active < int(scenes_.size()) && state_.models[size_t(active)].visible;
  if (!drawsFiblets(scene.settings.pipeline)) {
    // The baselines draw one raw tractogram: the active model's, once its
    // raw vertices are decoded (compute meanwhile, over every visible model).
    if (active_shown && scenes_[size_t(active)]->has_raw) {
      const ViewerModel& model = *scenes_[size_t(active)];
      scene.models = {active};
      scene.gpu = GpuScene{&model.fiblets, &model.raw};
      scene.layout = sceneLayout(scene.gpu.datasets);
      scene.gpu.fiber_scalars = model.fiblets.fiberLength().address;
      int visible = 0;
      for (const ModelInfo& m : state_.models) visible += m.visible;
      state_.baseline_draws_active_only = visible > 1;
      return scene;
    }
    scene.settings.pipeline = RenderPipeline::Compute;
  }
  for (size_t i = 0; i < scenes_.size(); ++i) {
    if (!state_.models[i].visible) continue;
    scene.models.push_back(int(i));
    scene.gpu.datasets.push_back(&scenes_[i]->fiblets);
  }
  try {
    scene.layout = sceneLayout(scene.gpu.datasets);
  } catch (const Error& e) {
    // Too many fiblets for one frame's keys: the active model alone (or
    // nothing), and the reason in the status line.
    state_.status = e.what();
    scene.models.clear();
    scene.gpu.datasets.clear();
    if (active_shown) {
      scene.models = {active};
      scene.gpu.datasets = {&scenes_[size_t(active)]->fiblets};
    }
    scene.layout = sceneLayout(scene.gpu.datasets);
  }
  // The scene's fiber lengths for the scalar colour mode (one dataset: its
  // own buffer; several: concatenated once per scene).
  if (scene.settings.color == ColorMode::Scalar && !scene.empty()) {
    try {
      finishFrame();  // a new concatenation may replace a buffer a frame reads
      scene.gpu.fiber_scalars = scene_lengths_->update(scene.layout);
    } catch (const Error& e) {
      state_.status = e.what();
    }
  }
  return scene;
}

bool ViewerApp::splitActive() const {
  const int n = int(scenes_.size());
  const SplitViewInfo& s = state_.split;
  return s.on && s.left >= 0 && s.left < n && s.right >= 0 && s.right < n;
}

FrameScene ViewerApp::modelScene(int model) {
  FrameScene scene;
  scene.settings = state_.settings;
  if (!drawsFiblets(scene.settings.pipeline)) scene.settings.pipeline = RenderPipeline::Compute;
  const ViewerModel& m = *scenes_[size_t(model)];
  scene.models = {model};
  scene.gpu.datasets = {&m.fiblets};
  scene.layout = sceneLayout(scene.gpu.datasets);
  scene.gpu.fiber_scalars = m.fiblets.fiberLength().address;  // one dataset: its own lengths
  addDissectionCuts(state_.dissection.set, scene.settings);
  try {
    cuts_->sync(state_.dissection);
    cuts_->apply(state_.dissection.set, scene.gpu);
  } catch (const Error& e) {
    state_.status = e.what();
  }
  scene.gpu.anatomy = anatomy_.gpu();
  return scene;
}

void ViewerApp::recordSplit(VkCommandBuffer cmd, const Camera& camera, const gpu::Buffer& out) {
  const int models[2] = {state_.split.left, state_.split.right};
  const Bounds shown = boundsUnion(scenes_[size_t(models[0])]->data->bounds, scenes_[size_t(models[1])]->data->bounds);
  const double factor = splitDistanceFactor(controller_.fittedBounds(), shown);
  if (factor != split_reported_factor_) {
    // The halves' scale as drawn (a model added this frame is framed before
    // its first split frame), for the record and the tests.
    split_reported_factor_ = factor;
    char line[160];
    std::snprintf(line, sizeof line, "split-view %d %d: each half's eye %.4fx as far as the view's", models[0],
                  models[1], factor);
    state_.status = line;
    std::fprintf(stderr, "fibscope view: %s\n", line);
  }
  for (const int k : {0, 1}) {
    const Camera half = splitHalfCamera(camera, k == 1, factor, shown);
    std::unique_ptr<FrameRenderer>& r = split_renderers_[k];
    if (!r) r = std::make_unique<FrameRenderer>(*context_, half.width, half.height, frameStages());
    else if (r->targets().width != half.width || r->targets().height != half.height) r->resize(half.width, half.height);
    const FrameScene scene = modelScene(models[k]);
    r->record(cmd, half, scene.settings, scene.gpu);
  }
  recordSplitCompose(cmd, split_renderers_[0]->targets().color, split_renderers_[1]->targets().color, out,
                     camera.width, camera.height);
}

// The baselines draw raw vertices, decoded when such a pipeline is first
// chosen for a model: on a thread (pollRawDecode uploads them), the frames
// going on with the compute pipeline meanwhile.
void ViewerApp::ensureRawFor(int model) {
  if (drawsFiblets(state_.settings.pipeline) || model < 0 || model >= int(scenes_.size())) return;
  const ViewerModel* m = scenes_[size_t(model)].get();
  if (m->has_raw || (raw_decode_ && raw_decode_->model == m)) return;
  cancelRawDecode();  // another model's: the active one matters
  const ModelData& data = *m->data;
  const std::string fbl_path = data.temporary ? std::string() : data.fbl.path();
  RawDecode decode;
  decode.model = m;
  decode.cancel = std::make_shared<std::atomic<bool>>(false);
  decode.points = std::async(std::launch::async, [fbl_path, source = data.source_path,
                                                  phantom = options_.phantom_streamlines, cancel = decode.cancel] {
    return decodeRawVertices(fbl_path, source, phantom, *cancel);
  });
  raw_decode_ = std::move(decode);
  state_.status = "decoding the raw vertices of " + data.name + " for the " +
                  std::string(renderPipelineName(state_.settings.pipeline)) + " pipeline (compute meanwhile)";
}

void ViewerApp::pollRawDecode() {
  if (!raw_decode_ || raw_decode_->points.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  RawDecode decode = std::move(*raw_decode_);
  raw_decode_.reset();
  auto it = std::find_if(scenes_.begin(), scenes_.end(), [&](const auto& m) { return m.get() == decode.model; });
  try {
    Tractogram points = decode.points.get();
    if (it == scenes_.end()) return;  // closed meanwhile
    finishFrame();  // the upload must not race the frame in flight
    ViewerModel& model = **it;
    model.raw = GpuRawTractogram::upload(*context_, points, model.data->name);
    model.has_raw = true;
    state_.status = "raw vertices of " + model.data->name + " ready";
  } catch (const Error& e) {
    if (it == scenes_.end()) return;
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
    state_.settings.pipeline = RenderPipeline::Compute;  // the baseline cannot draw this model
  }
}

void ViewerApp::cancelRawDecode() {
  if (!raw_decode_) return;
  raw_decode_->cancel->store(true);
  if (raw_decode_->points.valid()) raw_decode_->points.wait();  // stops at its next chunk
  raw_decode_.reset();
}

void ViewerApp::apply(const ViewerAction& action) {
  std::visit(
      [&](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, OrbitAction>) {
          controller_.rotate(a.dx, a.dy);
        } else if constexpr (std::is_same_v<A, PanAction>) {
          controller_.pan(a.dx, a.dy);
        } else if constexpr (std::is_same_v<A, DollyAction>) {
          controller_.dolly(a.steps);
        } else if constexpr (std::is_same_v<A, ViewAction>) {
          if (a.view) controller_.setStandardView(*a.view);
          else controller_.reset();
        } else if constexpr (std::is_same_v<A, ResizeAction>) {
          // The frame loop follows the framebuffer (window) or these sizes
          // (offscreen) and recreates the targets and swapchain.
          if (window_) window_->setSize(a.width, a.height);
          options_.width = a.width;
          options_.height = a.height;
        } else if constexpr (std::is_same_v<A, FovAction>) {
          controller_.setFovY(a.degrees);
          state_.fov_deg = controller_.fovY();
        } else if constexpr (std::is_same_v<A, SetAction>) {
          try {
            applySetting(state_.settings, a.key, a.value);
          } catch (const Error& e) {
            state_.status = e.what();
          }
        } else if constexpr (std::is_same_v<A, ScreenshotAction>) {
          takeScreenshot(a);
        } else if constexpr (std::is_same_v<A, OpenAction>) {
          openModel(a.path);  // on the worker: framed when it is added
        } else if constexpr (std::is_same_v<A, CloseModelAction>) {
          closeModel(a.model);
        } else if constexpr (std::is_same_v<A, ModelAction>) {
          if (a.model < 0 || a.model >= int(state_.models.size())) {
            state_.status = "model " + std::to_string(a.model) + ": no such model (" +
                            std::to_string(state_.models.size()) + " loaded)";
            std::fprintf(stderr, "fibscope view: %s\n", state_.status.c_str());
          } else if (a.op == ModelAction::Op::Activate) {
            state_.active_model = a.model;
          } else {
            state_.models[size_t(a.model)].visible = a.op == ModelAction::Op::Show;
          }
        } else if constexpr (std::is_same_v<A, PickAction>) {
          pickAt(a);
        } else if constexpr (std::is_same_v<A, ClearSelectionAction>) {
          selection_->clear();
          syncSelection();
        } else if constexpr (std::is_same_v<A, ExportSelectionAction>) {
          try {
            syncSelection();  // a model closed meanwhile takes its selection with it
            const ViewerSelection::Exported done = selection_->exportTck(a.path);
            state_.status = "exported " + std::to_string(done.written) + " fibers of " + done.model + " to " + a.path;
            if (done.left_out > 0)
              state_.status += " (" + std::to_string(done.left_out) +
                               " selected fibers of other models not written: one model per file)";
          } catch (const Error& e) {
            state_.status = e.what();
            std::fprintf(stderr, "fibscope view: %s\n", e.what());
          }
        } else if constexpr (std::is_same_v<A, ExpectSelectedAction>) {
          if (selection_->size() != a.count)
            throw Error(a.where + ": expect-selected " + std::to_string(a.count) + ": " +
                        std::to_string(selection_->size()) + " fibers are selected");
        } else if constexpr (std::is_same_v<A, DissectionAction> || std::is_same_v<A, RoiSetFileAction> ||
                             std::is_same_v<A, ExportKeptAction> || std::is_same_v<A, ExpectKeptAction> ||
                             std::is_same_v<A, RoiPlaceAction> || std::is_same_v<A, RoiDragAction> ||
                             std::is_same_v<A, RoiResizeAction>) {
          applyDissection(action);
        } else if constexpr (std::is_same_v<A, QuitAction>) {
          quit_ = true;
        } else if constexpr (std::is_same_v<A, TubesAction>) {
          state_.tubes.selection = a.selection;
          state_.tubes.filtered = a.filtered;
          state_.tubes.all = a.all;
          if (a.svo) state_.tubes.svo = TubesInfo::Svo(*a.svo);
          if (a.voxel_mm) state_.tubes.voxel_mm = *a.voxel_mm;
          if (a.svo_lod_px) state_.tubes.svo_lod_px = *a.svo_lod_px;
          if (a.radius_mm > 0) state_.tubes.radius_mm = a.radius_mm;
          if (a.radius_from) state_.tubes.radius_from = *a.radius_from;
          if (a.radius_min > 0) state_.tubes.radius_min = a.radius_min, state_.tubes.radius_max = a.radius_max;
          if (state_.tubes.wanted()) state_.show_tubes = true;  // as the panel's switches open it
        } else if constexpr (std::is_same_v<A, AnatomyAction>) {
          loadAnatomy(a.path);
        } else if constexpr (std::is_same_v<A, SliceStepAction>) {
          stepActiveSlice(state_, a.voxels);
        } else if constexpr (std::is_same_v<A, BundleAction>) {
          startBundle(a.params);
        } else if constexpr (std::is_same_v<A, CancelBundleAction>) {
          bundling_->cancel();
          if (bundle_load_job_) loader_->cancel(bundle_load_job_);
          bundle_load_job_ = 0;
          state_.bundling.running = false;
          state_.bundling.message = "bundling cancelled";
          state_.status = state_.bundling.message;
        } else if constexpr (std::is_same_v<A, ShowOnlyModelAction>) {
          if (a.model < 0 || a.model >= int(state_.models.size())) {
            state_.status = "show-model " + std::to_string(a.model) + ": no such model (" +
                            std::to_string(state_.models.size()) + " loaded)";
            std::fprintf(stderr, "fibscope view: %s\n", state_.status.c_str());
          } else {
            for (size_t i = 0; i < state_.models.size(); ++i) state_.models[i].visible = int(i) == a.model;
            state_.active_model = a.model;
          }
        } else if constexpr (std::is_same_v<A, SplitViewAction>) {
          const int n = int(state_.models.size());
          if (a.on && !(a.left >= 0 && a.left < n && a.right >= 0 && a.right < n)) {
            state_.status = "split-view " + std::to_string(a.left) + " " + std::to_string(a.right) +
                            ": no such model (" + std::to_string(n) + " loaded)";
            std::fprintf(stderr, "fibscope view: %s\n", state_.status.c_str());
          } else {
            state_.split = {a.on, a.on ? a.left : -1, a.on ? a.right : -1};
            split_reported_factor_ = 0;  // the next split frame reports its scale
          }
        } else if constexpr (std::is_same_v<A, SaveModelAction>) {
          saveModel(a);
        }
      },
      action);
}

void ViewerApp::applyDissection(const ViewerAction& action) {
  DissectionState& d = state_.dissection;
  auto report = [&](const std::string& message) {
    state_.status = message;
    std::fprintf(stderr, "fibscope view: %s\n", message.c_str());
  };
  auto selectedRoi = [&]() -> Roi* {
    return d.selected >= 0 && d.selected < int(d.set.rois.size()) ? &d.set.rois[size_t(d.selected)] : nullptr;
  };
  try {
    std::visit(
        [&](const auto& a) {
          using A = std::decay_t<decltype(a)>;
          if constexpr (std::is_same_v<A, DissectionAction>) {
            if (const auto* add = std::get_if<CutMeshAddEdit>(&a.edit)) {
              // The mesh read and uploaded first: a file that cannot be read changes nothing.
              finishFrame();
              const std::string warning = cuts_->prepare(add->cut.spec);
              applyDissectionEdit(d, state_.settings, a.edit);
              d.cut_mesh_message = warning.empty() ? "added cut " + meshCutSpec(add->cut) : warning;
              report(d.cut_mesh_message);
              return;
            }
            applyDissectionEdit(d, state_.settings, a.edit);
          } else if constexpr (std::is_same_v<A, RoiSetFileAction>) {
            if (a.save) {
              const AnatomyGrid* grid = anatomy_.gpu() ? &anatomy_.gpu()->grid() : nullptr;
              RoiSet set = roiSetToSave(d, state_.settings, grid);
              set.anatomy = state_.anatomy.loaded() ? state_.anatomy.path : "";
              saveRoiSet(set, a.path);
              d.file_message = "saved " + a.path;
            } else {
              // Read whole before anything changes: a bad file leaves the state.
              RoiSet set = loadRoiSet(a.path);
              const std::string anatomy = set.anatomy;
              const AnatomyGrid* grid = anatomy_.gpu() ? &anatomy_.gpu()->grid() : nullptr;
              loadRoiSetIntoState(std::move(set), d, state_.settings, grid);
              d.file_message = "loaded " + a.path;
              // The set's anatomy is shown (read while frames go on); a set
              // without one leaves the image shown as it is.
              if (!anatomy.empty() && anatomy != state_.anatomy.path) loadAnatomy(anatomy);
            }
            state_.status = d.file_message;
          } else if constexpr (std::is_same_v<A, ExportKeptAction>) {
            const int m = state_.active_model;
            if (m < 0 || m >= int(scenes_.size())) throw Error(a.path + ": no model to export from");
            const ModelData& data = *scenes_[size_t(m)]->data;
            DissectionExportSource source;
            source.model = data.name;
            source.path = data.source_path;
            source.phantom.streamlines = options_.phantom_streamlines;
            source.phantom.seed = loader_->options().phantom_seed;  // the loader's phantom, made again
            dissection_->startExport(d, source, a.path);
            d.exporting = true;
            state_.status = "exporting the kept fibers of " + data.name + " to " + a.path;
          } else if constexpr (std::is_same_v<A, ExpectKeptAction>) {
            currentScene(/*filter_now=*/true);
            const DissectionStats& stats = d.stats;
            if (!stats.error.empty())
              throw Error(a.where + ": expect-kept " + std::to_string(a.count) + ": " + stats.error);
            if (stats.kept != a.count)
              throw Error(a.where + ": expect-kept " + std::to_string(a.count) + ": " + std::to_string(stats.kept) +
                          " of " + std::to_string(stats.fibers) + " fibers are kept");
            std::fprintf(stderr, "fibscope view: %s: kept %llu of %llu fibers (last filter update %.1f ms)\n",
                         a.where.c_str(), static_cast<unsigned long long>(stats.kept),
                         static_cast<unsigned long long>(stats.fibers), stats.update_ms);
          } else if constexpr (std::is_same_v<A, RoiPlaceAction>) {
            placeRoiAt(a.x, a.y);
          } else if constexpr (std::is_same_v<A, RoiDragAction>) {
            if (Roi* roi = selectedRoi())
              if (const std::optional<glm::dvec3> at = regionCenter(roi->region))
                roi->region = movedRegion(roi->region, viewPlaneDrag(state_.camera, *at, a.dx, a.dy));
          } else if constexpr (std::is_same_v<A, RoiResizeAction>) {
            if (Roi* roi = selectedRoi()) roi->region = scaledRegion(roi->region, std::pow(1.1, a.steps));
          }
        },
        action);
  } catch (const Error& e) {
    if (std::holds_alternative<ExpectKeptAction>(action)) throw;  // the script fails, naming its line
    if (std::holds_alternative<RoiSetFileAction>(action)) d.file_message = e.what();
    if (const auto* edit = std::get_if<DissectionAction>(&action))
      if (std::holds_alternative<CutMeshAddEdit>(edit->edit)) d.cut_mesh_message = e.what();
    report(e.what());
  }
}

void ViewerApp::startBundle(const BundleParams& params) {
  BundlingInfo& b = state_.bundling;
  const int m = state_.active_model;
  try {
    if (m < 0 || m >= int(scenes_.size())) throw Error("bundle: no model to bundle");
    if (b.running) throw Error("bundle: a bundling job is running");
    const ModelData& data = *scenes_[size_t(m)]->data;
    ViewerBundleSource source;
    source.name = data.name;
    source.source_path = data.source_path;
    if (!data.temporary) source.fbl_path = data.fbl.path();
    source.phantom_streamlines = options_.phantom_streamlines;
    source.phantom_seed = loader_->options().phantom_seed;  // the loader's phantom, made again
    bundling_->start(source, params);
    b.params = params;
    b.running = true;
    b.source_model = m;
    b.bundled_model = -1;
    b.message.clear();
    bundle_source_id_ = scenes_[size_t(m)]->id;
    bundle_first_frame_ = frames_drawn_;
    state_.status = "bundling " + data.name;
    std::fprintf(stderr, "fibscope view: bundling %s (%s, R %.4g, %u iterations)\n", data.name.c_str(),
                 bundleModeName(params.mode), params.radius, params.iterations);
  } catch (const Error& e) {
    b.message = e.what();
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

void ViewerApp::pollBundling() {
  BundlingInfo& b = state_.bundling;
  if (const std::optional<ProgressSnapshot> p = bundling_->progress()) {
    b.progress.label = p->label;
    b.progress.unit = p->unit;
    b.progress.done = p->done;
    b.progress.total = p->total;
    b.progress.rate = p->rate;
    b.progress.eta_seconds = p->eta_seconds;
    b.progress.elapsed_seconds = p->elapsed_seconds;
  }
  if (!bundling_->running()) return;
  try {
    const std::optional<ViewerBundleResult> done = bundling_->poll();
    if (!bundling_->running() && !done) {  // cancelled
      b.running = false;
      return;
    }
    if (!done) return;
    for (const std::string& w : done->warnings) std::fprintf(stderr, "fibscope view: warning: %s\n", w.c_str());
    bundle_frames_ = frames_drawn_ - bundle_first_frame_;
    bundle_result_ = done;
    b.progress = LoadingInfo{};
    b.progress.label = "compressing the bundled copy";
    bundle_load_job_ = loader_->request(done->path);  // compressed to fiblets like any file
  } catch (const Error& e) {
    b.running = false;
    b.message = e.what();
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

void ViewerApp::bundledModelAdded() {
  BundlingInfo& b = state_.bundling;
  bundle_load_job_ = 0;
  b.running = false;
  const int added = int(state_.models.size()) - 1;  // addModel made it the active one
  b.bundled_model = added;
  bundled_exact_.emplace_back(scenes_[size_t(added)]->id, bundle_result_->exact_path);
  b.source_model = -1;
  for (size_t i = 0; i < scenes_.size(); ++i) {
    if (scenes_[i]->id == bundle_source_id_) {
      b.source_model = int(i);
      state_.models[i].visible = false;  // the bundled copy shown in its place
    }
  }
  char line[512];
  const ViewerBundleResult& r = *bundle_result_;
  std::snprintf(line, sizeof line,
                "bundled %s: %llu fibers, %llu points, displacement mean %.3f mm, max %.3f mm, %.2f s; "
                "%llu frames drawn while bundling, %llu progress reports; model %d",
                r.model.c_str(), static_cast<unsigned long long>(r.fibers), static_cast<unsigned long long>(r.points),
                r.mean_mm, r.max_mm, r.seconds, static_cast<unsigned long long>(bundle_frames_),
                static_cast<unsigned long long>(r.progress_reports), added);
  b.message = line;
  state_.status = line;
  std::fprintf(stderr, "fibscope view: %s\n", line);
}

void ViewerApp::saveModel(const SaveModelAction& save) {
  try {
    if (save.model < 0 || save.model >= int(scenes_.size()))
      throw Error("save-model " + std::to_string(save.model) + ": no such model (" +
                  std::to_string(scenes_.size()) + " loaded)");
    const ModelData& data = *scenes_[size_t(save.model)]->data;
    const uint64_t id = scenes_[size_t(save.model)]->id;
    const auto exact = std::find_if(bundled_exact_.begin(), bundled_exact_.end(),
                                    [&](const auto& e) { return e.first == id; });
    std::unique_ptr<TractogramReader> reader;
    if (exact != bundled_exact_.end()) {
      reader = openInput(exact->second);  // the bundled positions, not the fiblets' resampled ones
    } else if (!data.source_path.empty()) {
      reader = openInput(data.source_path);
    } else if (!data.temporary) {
      reader = openFbl(data.fbl.path());
    } else {
      PhantomOptions phantom;
      phantom.streamlines = options_.phantom_streamlines;
      phantom.seed = loader_->options().phantom_seed;
      reader = openPhantom(phantom);
    }
    const TractogramHeader header = reader->header();
    const Tractogram tractogram = readAllStreamlines(*reader);
    for (const std::string& w : writeBundledTractogram(save.path, tractogram, header, /*overwrite=*/false))
      std::fprintf(stderr, "fibscope view: warning: %s\n", w.c_str());
    state_.status = "saved " + data.name + " (" + std::to_string(tractogram.streamlineCount()) + " fibers) to " +
                    save.path;
    state_.bundling.message = state_.status;
    std::fprintf(stderr, "fibscope view: %s\n", state_.status.c_str());
  } catch (const Error& e) {
    state_.status = e.what();
    state_.bundling.message = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

void ViewerApp::placeRoiAt(double x, double y) {
  // On the fiber drawn there, else on the focal plane under the cursor.
  const PickResult pick = pickDrawn(x, y);
  const Camera& camera = drawn_ids_.empty() ? state_.camera : last_camera_;  // the camera of the G-buffer picked
  double depth = pick.depth;
  if (!pick.hit) {
    const std::array<double, 16> m = viewProjectionD(camera);
    const Vec3d& t = camera.target;
    const double z = m[2] * t[0] + m[6] * t[1] + m[10] * t[2] + m[14];
    const double w = m[3] * t[0] + m[7] * t[1] + m[11] * t[2] + m[15];
    depth = z / w;
  }
  const std::optional<Vec3d> at = unprojectPixel(camera, std::floor(x), std::floor(y), depth);
  if (!at) {
    state_.status = "no point to place a ROI at there";
    return;
  }
  DissectionState& d = state_.dissection;
  const std::string name = uniqueRoiName(d.set, "sphere");
  applyDissectionEdit(d, state_.settings,
                      RoiAddEdit{name, RoiRole::Include,
                                 sphereAt({(*at)[0], (*at)[1], (*at)[2]}, defaultRoiRadius(state_.scene_bounds))});
  char line[160];
  std::snprintf(line, sizeof line, "%s at %.1f, %.1f, %.1f mm (%s)", name.c_str(), (*at)[0], (*at)[1], (*at)[2],
                pick.hit ? "on the fiber there" : "on the focal plane");
  state_.status = line;
}

void ViewerApp::pollExport() {
  DissectionState& d = state_.dissection;
  try {
    const std::optional<DissectionExportResult> done = dissection_->pollExport();
    if (!done) return;
    d.exporting = false;
    for (const std::string& w : done->warnings) std::fprintf(stderr, "fibscope view: warning: %s\n", w.c_str());
    char line[512];
    std::snprintf(line, sizeof line, "exported %llu of %llu fibers of %s to %s in %.2f s", 
                  static_cast<unsigned long long>(done->kept), static_cast<unsigned long long>(done->streamlines),
                  done->model.c_str(), done->path.c_str(), done->seconds);
    d.file_message = line;
    if (done->groups > 0) d.file_message += " (" + std::to_string(done->groups) + " ROI groups)";
    state_.status = d.file_message;
    std::fprintf(stderr, "fibscope view: %s\n", d.file_message.c_str());
  } catch (const Error& e) {
    d.exporting = false;
    d.file_message = e.what();
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

std::string ViewerApp::freshScreenshotPath() {
  for (;;) {
    char name[64];
    std::snprintf(name, sizeof(name), "fibscope-%03d.png", ++screenshot_counter_);
    if (!std::filesystem::exists(name)) return name;
  }
}

void ViewerApp::takeScreenshot(const ScreenshotAction& shot) {
  const std::string path = shot.path.empty() ? freshScreenshotPath() : shot.path;
  if (shot.width == 0) {
    pending_shot_ = path;  // after this frame is drawn, panels included
    return;
  }
  // The scene alone at the chosen size, from where the animation is going.
  try {
    finishFrame();
    controller_.finishAnimation();
    if (!shot_renderer_)
      shot_renderer_ = std::make_unique<FrameRenderer>(*context_, shot.width, shot.height, frameStages());
    shot_renderer_->resize(shot.width, shot.height);
    const Camera camera = viewCamera(shot.width, shot.height);
    if (splitActive()) {
      // The split view at the shot's size, composed in the shot's colour buffer.
      gpu::submitOnce(*context_, [&](VkCommandBuffer cmd) { recordSplit(cmd, camera, shot_renderer_->targets().color); });
      for (auto& r : split_renderers_) r->collect();
    } else {
      const FrameScene scene = currentScene();
      if (scene.empty()) throw Error("screenshot: no visible model to draw");
      syncSelection(scene);
      shot_renderer_->render(camera, scene.settings, withSelection(scene));
    }
    writePngRgba(path, shot.width, shot.height, downloadColor(*context_, shot_renderer_->targets()));
    controller_.setViewport(presentation_.width, presentation_.height);  // camera() noted the shot's size
    state_.status = "saved " + path;
  } catch (const Error& e) {
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

void ViewerApp::syncSelection(const FrameScene& scene) {
  // Every loaded model may hold selected fibers; those drawn in `scene`
  // are highlighted at their scene-global ids.
  std::vector<SelectionModel> models;
  for (size_t i = 0; i < scenes_.size(); ++i) {
    const ViewerModel& model = *scenes_[i];
    SelectionModel m;
    m.id = model.id;
    m.name = model.data->name;
    m.dataset = &model.fiblets;
    m.fbl = &model.data->fbl;
    m.path = model.data->source_path;
    for (size_t k = 0; k < scene.models.size(); ++k)
      if (scene.models[k] == int(i)) m.fiber_base = scene.layout.entries[k].fiber_base;
    models.push_back(std::move(m));
  }
  try {
    finishFrame();  // uploads wait for the queue; the frame in flight reads the bits
    selection_->sync(models, scene.layout.fibers, activeModelId(), state_.selection);
  } catch (const Error& e) {
    state_.status = e.what();
  }
}

void ViewerApp::syncTubes(const FrameScene& scene) {
  TubesInfo& info = state_.tubes;
  // What the tubes are of: the wanted sets, their radius and tolerance,
  // the scene's models and numbering, and the selection's or the kept
  // bits' state (read only when they change).
  std::string key;
  if (info.wanted() && !scene.empty()) {
    key = std::to_string(info.selection) + std::to_string(info.filtered) + std::to_string(info.all) + "|" +
          std::to_string(info.radius_mm) +
          "|" + info.radius_from + ":" + std::to_string(info.radius_min) + "," + std::to_string(info.radius_max) +
          "|" + std::to_string(info.tolerance_mm) + "|";
    for (size_t k = 0; k < scene.models.size(); ++k)
      key += std::to_string(scenes_[size_t(scene.models[k])]->id) + ":" +
             std::to_string(scene.layout.entries[k].fiber_base) + ",";
    if (info.selection && !info.all) key += "|selection " + std::to_string(selection_->revision());
    if (info.filtered && !info.all) key += "|" + dissection_->keptKey();
  }
  const auto sources = [&]() {
    std::vector<ViewerTubeSource> out(scene.models.size());
    std::vector<std::vector<bool>> taken(scene.models.size());
    for (size_t k = 0; k < scene.models.size(); ++k) {
      const ViewerModel& m = *scenes_[size_t(scene.models[k])];
      out[k].fbl = std::shared_ptr<const FblFile>(m.data, &m.data->fbl);  // the worker holds the model's file
      out[k].fiber_base = scene.layout.entries[k].fiber_base;
      taken[k].assign(m.data->streamlines, false);
    }
    const auto add = [&](size_t k, uint32_t fiber) {
      if (fiber < taken[k].size() && !taken[k][fiber]) {
        taken[k][fiber] = true;
        out[k].fibers.push_back(fiber);
      }
    };
    if (info.all) {
      for (size_t k = 0; k < scene.models.size(); ++k)
        for (uint32_t f = 0; f < taken[k].size(); ++f) add(k, f);
      return out;
    }
    if (info.selection)
      for (const SelectedEntry& e : selection_->entries())
        for (size_t k = 0; k < scene.models.size(); ++k)
          if (scenes_[size_t(scene.models[k])]->id == e.model) add(k, e.fiber);
    if (info.filtered) {
      const std::optional<std::vector<uint32_t>> kept = dissection_->keptSceneFibers(state_.dissection);
      if (!kept) throw Error("tubes: no dissection criteria to take the kept fibers of");
      for (const uint32_t global : *kept)
        if (const std::optional<SceneFiber> at = locateSceneFiber(scene.layout, global)) add(at->dataset, at->fiber);
    }
    return out;
  };
  ViewerTubeRequest request;
  request.svo = info.svo;
  request.voxel_mm = info.voxel_mm;
  request.distance_field = distanceFieldAoRuns(state_.settings) || distanceFieldShadowsRun(state_.settings);
  request.df_voxel_mm = state_.settings.df_voxel_mm;
  const std::string message = info.message;
  const bool was_building = info.building;
  std::vector<std::string> warnings;
  try {
    tubes_->update(key, sources, request, info, &warnings);
  } catch (const Error& e) {
    info.message = e.what();
  }
  for (const std::string& w : warnings) {
    std::fprintf(stderr, "fibscope view: warning: %s\n", w.c_str());
    state_.status = w;
  }
  // The panel's line, on stderr too (scripts and tests read it there).
  if (!info.message.empty() && info.message != message) std::fprintf(stderr, "fibscope view: %s\n", info.message.c_str());
  if (was_building && !info.building && info.message.empty() && info.svo_leaves > 0 && !info.svo_kept)
    std::fprintf(stderr,
                 "fibscope view: svo: %llu tubes, %llu segments, voxel %.4f mm, %u^3 grid, %llu leaves, nodes %llu "
                 "bytes, decoration %llu bytes, %s in %.3f s\n",
                 static_cast<unsigned long long>(info.fibers), static_cast<unsigned long long>(info.segments),
                 double(info.svo_voxel), info.svo_side, static_cast<unsigned long long>(info.svo_leaves),
                 static_cast<unsigned long long>(info.svo_nodes_bytes),
                 static_cast<unsigned long long>(info.svo_decoration_bytes),
                 info.svo_from_cache ? "read from the cache" : "built", info.svo_seconds);
  if (was_building && !info.building && info.message.empty() && info.df_bytes > 0)
    std::fprintf(stderr, "fibscope view: distance field: voxel %.4f mm, %.1f MB, built in %.3f s\n",
                 double(info.df_voxel), double(info.df_bytes) / 1e6, info.df_seconds);
}

PickResult ViewerApp::pickDrawn(double x, double y) {
  finishFrame();
  if (drawn_ids_.empty() || !(x >= 0 && y >= 0 && x < presentation_.width && y < presentation_.height)) return {};
  // The G-buffer of the renderer that drew it (a coarse frame's is
  // smaller): window pixels scaled to its size.
  const GpuFrameTargets& drawn = (recorded_renderer_ ? recorded_renderer_ : renderer_.get())->targets();
  return pickFiber(*context_, drawn, uint32_t(uint64_t(x) * drawn.width / presentation_.width),
                   uint32_t(uint64_t(y) * drawn.height / presentation_.height));
}

void ViewerApp::pickAt(const PickAction& pick) {
  try {
    // The G-buffer holds the last frame drawn: its scene-global fiber ids
    // map to (model, fiber) through that frame's layout.
    std::optional<SelectedEntry> hit;
    std::string what = "no fiber there: ";
    {
      const PickResult result = pickDrawn(pick.x, pick.y);
      if (result.hit) {
        if (const std::optional<SceneFiber> at = locateSceneFiber(drawn_layout_, result.fiber)) {
          hit = SelectedEntry{drawn_ids_[at->dataset], at->fiber};
          what = "fiber " + std::to_string(at->fiber) + " of ";
          for (const auto& m : scenes_)
            if (m->id == hit->model) what += m->data->name;
          what += ": ";
        }
      }
    }
    syncSelection();  // knows the models the hit may name
    selection_->pick(hit, pick.add);
    syncSelection();
    const size_t n = selection_->size();
    state_.status = what + std::to_string(n) + (n == 1 ? " fiber" : " fibers") + " selected";
  } catch (const Error& e) {
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

GpuScene ViewerApp::withSelection(const FrameScene& scene) const {
  // The bits were uploaded for this scene's numbering by syncSelection(scene).
  GpuScene gpu = scene.gpu;
  if (!scene.dissection_selects) gpu.selection_bits = selection_->bits();
  gpu.anatomy = anatomy_.gpu();  // the slices with whatever models are drawn
  return gpu;
}

void ViewerApp::finishFrame() {
  if (!in_flight_) return;
  VK_CHECK(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  in_flight_ = false;
  // Submission to completion (an upper bound of the GPU's time: lavapipe's
  // timestamps are not trusted) of the last full-detail frame.
  const double submitted_ms = std::chrono::duration<double, std::milli>(Clock::now() - submitted_at_).count();
  if (submitted_coarse_) last_coarse_frame_ms_ = submitted_ms;
  else last_full_frame_ms_ = submitted_ms;
  state_.coarse_frame = submitted_coarse_;
  FrameRecord record;
  record.frame_ms = last_frame_ms_;
  record.gpu = (recorded_renderer_ ? recorded_renderer_ : renderer_.get())->collect();
  if (split_recorded_ && split_renderers_[1]) {
    // The right half's passes too: the frame's GPU time is both halves'.
    const FrameStats right = split_renderers_[1]->collect();
    record.gpu.gpu_ms += right.gpu_ms;
    record.gpu.passes.insert(record.gpu.passes.end(), right.passes.begin(), right.passes.end());
  }
  state_.addFrame(std::move(record));
}

void ViewerApp::resizeTo(uint32_t width, uint32_t height) {
  finishFrame();
  vkDeviceWaitIdle(context_->device());
  renderer_->resize(width, height);
  drawn_layout_ = {};  // the G-buffer is new: nothing to pick until a frame is drawn
  drawn_ids_.clear();
  resizePresentation(*context_, presentation_, width, height);
  if (window_) {
    gpu::recreateSwapchain(*context_, swapchain_, width, height);
    swapchain_stale_ = false;
  }
}

void ViewerApp::recordFrame(VkCommandBuffer cmd, uint32_t width, uint32_t height, const Camera& camera,
                            const FrameScene& scene) {
  drawn_layout_ = {};
  drawn_ids_.clear();
  frame_coarse_ = false;
  recorded_renderer_ = nullptr;
  split_recorded_ = false;
  if (splitActive()) {
    // Two models side by side (no picking: nothing is numbered for it).
    // No frame is in flight here (drawFrame's currentScene waited for it).
    recordSplit(cmd, camera, renderer_->targets().color);
    recorded_renderer_ = split_renderers_[0].get();
    split_recorded_ = true;
  } else if (!scene.empty()) {
    RenderSettings settings = scene.settings;
    // Adaptive detail (adaptive_detail.h). Moving: the camera differs from
    // the last frame's (slow frames settle the controller's smoothing within
    // one update, so animating() alone would miss a steady orbit).
    const bool moving = controller_.animating() || !sameView(camera, last_camera_);
    last_camera_ = camera;
    if (drawCoarse(state_.adaptive_detail, settings, moving, last_full_frame_ms_)) {
      settings = coarseSettings(settings, state_.moving_lod_px);
      frame_coarse_ = true;
    }
    if (frame_coarse_) {
      // At half (or, where that is still slow, quarter) resolution: the
      // coarse frame is bound by its pixels (long LoD segments); stretched
      // over the window's colour buffer.
      coarse_divisor_ = coarseDivisor(coarse_divisor_, last_coarse_frame_ms_);
      const uint32_t half_width = std::max(1u, width / coarse_divisor_),
                     half_height = std::max(1u, height / coarse_divisor_);
      if (!coarse_renderer_)
        coarse_renderer_ = std::make_unique<FrameRenderer>(*context_, half_width, half_height, frameStages());
      else if (coarse_renderer_->targets().width != half_width || coarse_renderer_->targets().height != half_height)
        coarse_renderer_->resize(half_width, half_height);
      if (!upscale_ready_) {
        upscale_ = createUpscalePass(*context_);
        upscale_ready_ = true;
      }
      Camera half = camera;
      half.width = half_width;
      half.height = half_height;
      coarse_renderer_->record(cmd, half, settings, withSelection(scene));
      gpu::computeToComputeBarrier(cmd);
      recordUpscale(cmd, upscale_, coarse_renderer_->targets().color, half_width, half_height,
                    renderer_->targets().color, width, height);
      recorded_renderer_ = coarse_renderer_.get();
    } else {
      renderer_->record(cmd, camera, settings, withSelection(scene));
      recorded_renderer_ = renderer_.get();
    }
    drawn_layout_ = scene.layout;
    for (const int m : scene.models) drawn_ids_.push_back(scenes_[size_t(m)]->id);
  } else {
    // Nothing to draw: the background alone (RGBA8, R in the low byte).
    auto byte = [](float v) { return uint32_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };
    const auto& bg = state_.settings.background;
    const uint32_t packed = byte(bg[0]) | byte(bg[1]) << 8 | byte(bg[2]) << 16 | 0xFF000000u;
    vkCmdFillBuffer(cmd, renderer_->targets().color.buffer, 0, uint64_t(width) * height * 4, packed);
    // Read next by the copy into the presentation image (a transfer). All
    // transfer stages: validation layers file the fill under COPY, the
    // spec under CLEAR.
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
  }
  recordCopyColorToPresentation(cmd, renderer_->targets().color, presentation_);
  beginPresentationPass(cmd, presentation_);
  imgui_->record(cmd);
  endPresentationPass(cmd, presentation_);
}

// One frame; false when it was skipped (swapchain out of date, minimised).
bool ViewerApp::drawFrame(uint32_t width, uint32_t height, double dt) {
  uint32_t image_index = 0;
  if (window_) {
    if (swapchain_stale_ || swapchain_.swapchain == VK_NULL_HANDLE) {
      gpu::recreateSwapchain(*context_, swapchain_, width, height);
      swapchain_stale_ = false;
      if (swapchain_.swapchain == VK_NULL_HANDLE) return false;
    }
    if (gpu::acquireSwapchainImage(*context_, swapchain_, image_index) == gpu::SwapchainStatus::OutOfDate) {
      swapchain_stale_ = true;
      return false;
    }
  }

  imgui_->newFrame(width, height, dt);
  state_.camera = controller_.camera(width, height);  // the panel's focal point and the ROIs' outlines
  // The dissection panel opens with the first ROI or plane (once: closed
  // again, it stays closed).
  if (!dissection_opened_ && (!state_.dissection.set.rois.empty() || !state_.dissection.set.clip_planes.empty() ||
                              !state_.dissection.set.cut_meshes.empty())) {
    state_.show_dissection = true;
    dissection_opened_ = true;
  }
  for (const ViewerAction& action : drawViewerUi(state_)) apply(action);
  // A model added or closed: the camera's box takes in every visible model
  // (the first framed, later ones keeping the user's view: refit). Show,
  // hide and switching the active model keep the view (the user may hide a
  // model to look inside another).
  frameIfModelsChanged();
  std::vector<uint64_t> visible_ids;
  for (size_t i = 0; i < scenes_.size(); ++i)
    if (state_.models[i].visible) visible_ids.push_back(scenes_[i]->id);
  if (visible_ids != scalar_range_ids_) fitScalarRange();
  ensureRawFor(state_.active_model);
  if (state_.fov_deg != controller_.fovY()) controller_.setFovY(state_.fov_deg);
  const Camera camera = viewCamera(width, height);
  const FrameScene scene = currentScene();
  syncSelection(scene);  // the highlight's bits for this frame (nothing in flight now)
  syncTubes(scene);

  VK_CHECK(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd_, &begin));
  try {
    recordFrame(cmd_, width, height, camera, scene);
  } catch (const Error& e) {
    // Settings the renderer refuses: show why, draw with the defaults next.
    VK_CHECK(vkEndCommandBuffer(cmd_));
    ImGui::EndFrame();
    state_.status = e.what();
    state_.settings = RenderSettings{};
    if (window_) swapchain_stale_ = true;  // the acquired image is given back by recreating
    return false;
  }
  if (window_) recordBlitToSwapchain(cmd_, presentation_, swapchain_.images[image_index], swapchain_.extent);
  VK_CHECK(vkEndCommandBuffer(cmd_));

  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;  // the blit is the first use
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd_;
  if (window_) {
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &swapchain_.acquired;
    submit.pWaitDstStageMask = &wait_stage;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &swapchain_.rendered[image_index];
  }
  VK_CHECK(vkResetFences(context_->device(), 1, &fence_));
  gpu::throwIfFailed(vkQueueSubmit(context_->queue(), 1, &submit, fence_), "vkQueueSubmit (frame)");
  in_flight_ = true;
  submitted_at_ = Clock::now();
  submitted_coarse_ = frame_coarse_;
  if (window_ && gpu::presentSwapchainImage(*context_, swapchain_, image_index) == gpu::SwapchainStatus::OutOfDate)
    swapchain_stale_ = true;

  if (pending_shot_) {
    const std::string path = *pending_shot_;
    pending_shot_.reset();
    try {
      finishFrame();
      writePngRgba(path, presentation_.width, presentation_.height, downloadPresentation(*context_, presentation_));
      state_.status = "saved " + path;
    } catch (const Error& e) {
      state_.status = e.what();
      std::fprintf(stderr, "fibscope view: %s\n", e.what());
    }
  }
  return true;
}

void ViewerApp::run() {
  uint32_t frames_done = 0;
  std::vector<double> frame_times_ms;
  frame_start_ = Clock::now();
  while (!quit_) {
    uint32_t width = options_.width, height = options_.height;
    if (window_) {
      window_->pollEvents();
      if (window_->shouldClose()) break;
      window_->framebufferSize(width, height);
      if (width == 0 || height == 0) {  // minimised
        window_->waitEvents();
        continue;
      }
    }
    finishFrame();
    pollLoads();  // after the fence: uploads run on this thread, nothing in flight
    pollAnatomy();
    pollRawDecode();
    pollExport();
    pollBundling();
    // Frames and the script count once the models named at start are in.
    const bool starting = !startup_jobs_.empty();
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - frame_start_).count();
    last_frame_ms_ = dt * 1000.0;
    frame_start_ = now;

    if (width != presentation_.width || height != presentation_.height) resizeTo(width, height);
    controller_.setViewport(width, height);

    if (window_)
      for (const InputEvent& event : window_->takeEvents())
        for (const ViewerAction& action : input_.map(event, imgui_->wantsMouse(), imgui_->wantsKeyboard()))
          apply(action);
    if (!starting)
      for (const ViewerAction& action : script_.nextFrame(loader_->busy() || anatomy_.loading() || state_.tubes.building,
                                                                  dissection_->exporting(),
                                                                  state_.bundling.running)) apply(action);
    if (!starting && options_.orbit_deg_per_frame != 0)
      controller_.rotate(options_.orbit_deg_per_frame / OrbitController::kDegreesPerPixel, 0);
    // A quit still draws this frame: a screenshot asked for with it is taken.
    controller_.update(dt);

    if (drawFrame(width, height, dt)) {
      ++frames_drawn_;
      if (!starting) {
        ++frames_done;
        // The wall time since the previous frame began (the first counted
        // frame's interval still holds loading: left out).
        if (frames_done > 1) frame_times_ms.push_back(last_frame_ms_);
      }
    }
    // Offscreen nothing paces the frames: while a load runs, leave the
    // cores to the worker (a window is paced by vsync).
    if (!window_ && (loader_->busy() || anatomy_.loading() || bundling_->running())) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const bool frames_done_enough = options_.frames > 0 && frames_done >= options_.frames;
    const bool script_done = !script_.empty() && script_.finished() && !starting;
    if (!window_ || options_.frames > 0 || !script_.empty()) {
      // Runs that stop by themselves: after the frames and the script.
      if ((options_.frames == 0 || frames_done_enough) && (script_.empty() || script_done)) break;
    }
  }
  finishFrame();
  if (!options_.screenshot.empty()) {
    writePngRgba(options_.screenshot, presentation_.width, presentation_.height,
                 downloadPresentation(*context_, presentation_));
  }
  if (options_.orbit_deg_per_frame != 0) printFrameSummary(frame_times_ms);
  if (options_.validate) {
    const int errors = context_->log().errors(), warnings = context_->log().warnings();
    if (errors + warnings > 0)
      throw Error("validation layers reported " + std::to_string(errors) + " errors and " + std::to_string(warnings) +
                  " warnings (printed above)");
  }
}

void ViewerApp::printFrameSummary(std::vector<double> frame_ms) const {
  if (frame_ms.empty()) {
    std::fprintf(stderr, "fibscope view: no frame timed\n");
    return;
  }
  std::sort(frame_ms.begin(), frame_ms.end());
  double sum = 0;
  for (double ms : frame_ms) sum += ms;
  const double mean = sum / double(frame_ms.size());
  const double median = frame_ms[frame_ms.size() / 2];
  const double p95 = frame_ms[std::min(frame_ms.size() - 1, size_t(double(frame_ms.size()) * 0.95))];
  // GPU time of the frames still in the overlay's history.
  double gpu = 0;
  for (const FrameRecord& r : state_.frames) gpu += r.gpu.gpu_ms;
  if (!state_.frames.empty()) gpu /= double(state_.frames.size());
  std::fprintf(stderr,
               "fibscope view: %zu frames at %ux%u on %s: frame (wall) mean %.2f ms, median %.2f ms, p95 %.2f ms "
               "(%.1f fps median); GPU mean %.2f ms over the last %zu\n",
               frame_ms.size(), presentation_.width, presentation_.height, context_->info().name.c_str(), mean, median,
               p95, median > 0 ? 1000.0 / median : 0.0, gpu, state_.frames.size());
}

}  // namespace

void runViewer(const ViewerOptions& options) {
  ViewerApp app(options);
  app.run();
}

}  // namespace fibscope
