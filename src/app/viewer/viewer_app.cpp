#include "app/viewer/viewer_app.h"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <type_traits>

#include "app/render_scene.h"
#include "app/viewer/imgui_layer.h"
#include "app/viewer/presentation.h"
#include "app/viewer/viewer_input.h"
#include "app/viewer/viewer_script.h"
#include "app/viewer/viewer_state.h"
#include "app/viewer/viewer_ui.h"
#include "app/viewer/viewer_window.h"
#include "core/error.h"
#include "gpu/submit.h"
#include "gpu/swapchain.h"
#include "gpu/vk_check.h"
#include "render/gpu_frame_renderer.h"
#include "render/orbit_controller.h"
#include "render/reference_raster.h"

namespace fibscope {
namespace {

using Clock = std::chrono::steady_clock;

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
  void openModel(const std::string& path);
  void frameActiveModel();
  const LoadedScene* activeScene();
  bool ensureRawFor(int model);
  void resizeTo(uint32_t width, uint32_t height);
  // Waits for the frame in flight and records its statistics.
  void finishFrame();
  bool drawFrame(uint32_t width, uint32_t height, double dt);
  void recordFrame(VkCommandBuffer cmd, uint32_t width, uint32_t height, const Camera& camera);
  void takeScreenshot(const ScreenshotAction& shot);
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
  std::vector<std::unique_ptr<LoadedScene>> scenes_;  // index-aligned with state_.models
  int framed_model_ = -1;  // the model the camera was last framed on

  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool in_flight_ = false;
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
  }
  presentation_ = createPresentation(*context_, width, height);
  imgui_ = std::make_unique<ImGuiLayer>(*context_, presentation_.render_pass, window_ ? window_->handle() : nullptr);
  renderer_ = std::make_unique<FrameRenderer>(*context_, width, height);

  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = context_->commandPool();
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  gpu::throwIfFailed(vkAllocateCommandBuffers(context_->device(), &alloc, &cmd_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  gpu::throwIfFailed(vkCreateFence(context_->device(), &fence_info, nullptr, &fence_), "vkCreateFence");

  controller_.setViewport(width, height);
  if (options_.files.empty()) openModel("");
  for (const std::string& file : options_.files) openModel(file);
  // A file named on the command line that cannot be read ends the run (as
  // `render` does); from the UI it only shows the error.
  if (!state_.status.empty() && state_.models.size() < std::max<size_t>(options_.files.size(), 1))
    throw Error(state_.status);
  if (!state_.models.empty()) state_.active_model = 0;
  frameActiveModel();
}

ViewerApp::~ViewerApp() { release(); }

void ViewerApp::release() {
  if (!context_) return;
  vkDeviceWaitIdle(context_->device());
  imgui_.reset();
  shot_renderer_.reset();
  renderer_.reset();
  scenes_.clear();
  destroyPresentation(*context_, presentation_);
  if (swapchain_.swapchain != VK_NULL_HANDLE) gpu::destroySwapchain(*context_, swapchain_);
  if (fence_ != VK_NULL_HANDLE) vkDestroyFence(context_->device(), fence_, nullptr);
  if (cmd_ != VK_NULL_HANDLE) vkFreeCommandBuffers(context_->device(), context_->commandPool(), 1, &cmd_);
  fence_ = VK_NULL_HANDLE;
  cmd_ = VK_NULL_HANDLE;
  context_.reset();
}

void ViewerApp::openModel(const std::string& path) {
  SceneOptions scene_options;
  scene_options.path = path;
  scene_options.phantom_streamlines = options_.phantom_streamlines;
  scene_options.upload_raw = state_.settings.pipeline != RenderPipeline::Compute;
  scene_options.progress = false;
  try {
    const auto start = Clock::now();
    finishFrame();  // the upload must not race the frame in flight
    auto scene = std::make_unique<LoadedScene>(loadScene(*context_, scene_options));
    ModelInfo info;
    info.name = path.empty() ? scene->name : std::filesystem::path(path).filename().string();
    info.path = path;
    info.streamlines = scene->streamlines;
    info.segments = scene->segments;
    info.fiblets = scene->fiblets.block().fiblet_count;
    info.load_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    state_.models.push_back(info);
    scenes_.push_back(std::move(scene));
    state_.active_model = int(state_.models.size()) - 1;
    state_.status = "opened " + info.name;
  } catch (const Error& e) {
    state_.status = e.what();  // one line; the viewer keeps running
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

void ViewerApp::frameActiveModel() {
  if (state_.active_model < 0) return;
  const LoadedScene& scene = *scenes_[size_t(state_.active_model)];
  controller_.frame(scene.bounds, scene.sample);
  framed_model_ = state_.active_model;
}

const LoadedScene* ViewerApp::activeScene() {
  const int m = state_.active_model;
  if (m < 0 || m >= int(scenes_.size()) || !state_.models[size_t(m)].visible) return nullptr;
  return scenes_[size_t(m)].get();
}

// The baselines draw raw vertices: a model opened for the compute pipeline
// only is read again with them when such a pipeline is chosen.
bool ViewerApp::ensureRawFor(int model) {
  if (state_.settings.pipeline == RenderPipeline::Compute || model < 0 || scenes_[size_t(model)]->has_raw)
    return true;
  SceneOptions scene_options;
  scene_options.path = state_.models[size_t(model)].path;
  scene_options.phantom_streamlines = options_.phantom_streamlines;
  scene_options.upload_raw = true;
  scene_options.progress = false;
  try {
    finishFrame();
    vkDeviceWaitIdle(context_->device());
    scenes_[size_t(model)].reset();
    scenes_[size_t(model)] = std::make_unique<LoadedScene>(loadScene(*context_, scene_options));
    return true;
  } catch (const Error& e) {
    state_.status = e.what();
    state_.settings.pipeline = RenderPipeline::Compute;
    return false;
  }
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
          openModel(a.path);
          frameActiveModel();
        } else if constexpr (std::is_same_v<A, QuitAction>) {
          quit_ = true;
        }
      },
      action);
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
    const LoadedScene* scene = activeScene();
    if (!scene) throw Error("screenshot: no visible model to draw");
    if (!shot_renderer_) shot_renderer_ = std::make_unique<FrameRenderer>(*context_, shot.width, shot.height);
    shot_renderer_->resize(shot.width, shot.height);
    const Camera camera = controller_.camera(shot.width, shot.height);
    shot_renderer_->render(camera, state_.settings, scene->gpuScene());
    writePngRgba(path, shot.width, shot.height, downloadColor(*context_, shot_renderer_->targets()));
    controller_.setViewport(presentation_.width, presentation_.height);  // camera() noted the shot's size
    state_.status = "saved " + path;
  } catch (const Error& e) {
    state_.status = e.what();
    std::fprintf(stderr, "fibscope view: %s\n", e.what());
  }
}

void ViewerApp::finishFrame() {
  if (!in_flight_) return;
  VK_CHECK(vkWaitForFences(context_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
  in_flight_ = false;
  FrameRecord record;
  record.frame_ms = last_frame_ms_;
  record.gpu = renderer_->collect();
  state_.addFrame(std::move(record));
}

void ViewerApp::resizeTo(uint32_t width, uint32_t height) {
  finishFrame();
  vkDeviceWaitIdle(context_->device());
  renderer_->resize(width, height);
  resizePresentation(*context_, presentation_, width, height);
  if (window_) {
    gpu::recreateSwapchain(*context_, swapchain_, width, height);
    swapchain_stale_ = false;
  }
}

void ViewerApp::recordFrame(VkCommandBuffer cmd, uint32_t width, uint32_t height, const Camera& camera) {
  const LoadedScene* scene = activeScene();
  if (scene) {
    renderer_->record(cmd, camera, state_.settings, scene->gpuScene());
  } else {
    // Nothing to draw: the background alone (RGBA8, R in the low byte).
    auto byte = [](float v) { return uint32_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };
    const auto& bg = state_.settings.background;
    const uint32_t packed = byte(bg[0]) | byte(bg[1]) << 8 | byte(bg[2]) << 16 | 0xFF000000u;
    vkCmdFillBuffer(cmd, renderer_->targets().color.buffer, 0, uint64_t(width) * height * 4, packed);
    gpu::memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
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
  for (const ViewerAction& action : drawViewerUi(state_)) apply(action);
  if (state_.active_model != framed_model_) frameActiveModel();
  ensureRawFor(state_.active_model);
  if (state_.fov_deg != controller_.fovY()) controller_.setFovY(state_.fov_deg);
  const Camera camera = controller_.camera(width, height);

  VK_CHECK(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd_, &begin));
  try {
    recordFrame(cmd_, width, height, camera);
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
    for (const ViewerAction& action : script_.nextFrame()) apply(action);
    // A quit still draws this frame: a screenshot asked for with it is taken.
    controller_.update(dt);

    if (drawFrame(width, height, dt)) ++frames_done;
    const bool frames_done_enough = options_.frames > 0 && frames_done >= options_.frames;
    const bool script_done = !script_.empty() && script_.finished();
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
  if (options_.validate) {
    const int errors = context_->log().errors(), warnings = context_->log().warnings();
    if (errors + warnings > 0)
      throw Error("validation layers reported " + std::to_string(errors) + " errors and " + std::to_string(warnings) +
                  " warnings (printed above)");
  }
}

}  // namespace

void runViewer(const ViewerOptions& options) {
  ViewerApp app(options);
  app.run();
}

}  // namespace fibscope
