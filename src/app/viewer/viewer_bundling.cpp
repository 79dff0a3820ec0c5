#include "app/viewer/viewer_bundling.h"

#include <unistd.h>

#include <cctype>
#include <chrono>
#include <filesystem>
#include <system_error>

#include "app/bundle_output.h"
#include "app/open_input.h"
#include "bundling/bundle_quality.h"
#include "bundling/bundle_setup.h"
#include "bundling/gpu/gpu_bundler.h"
#include "codec/fbl_reader.h"
#include "core/error.h"
#include "gpu/vulkan_context.h"
#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"

namespace fibscope {

namespace {

std::string bundledFileName(const std::string& name, uint64_t job) {
  std::string stem = std::filesystem::path(name).stem().string();
  for (char& c : stem)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')) c = '_';
  if (stem.empty()) stem = "model";
  return stem + "-bundled-" + std::to_string(job);
}

}  // namespace

ViewerBundling::ViewerBundling(std::string device_name, std::shared_ptr<gpu::DebugLog> validation_log)
    : device_name_(std::move(device_name)), validation_log_(std::move(validation_log)) {}

ViewerBundling::~ViewerBundling() {
  cancel();
  std::error_code ec;
  for (const std::string& f : temp_files_) std::filesystem::remove(f, ec);
  if (!temp_dir_.empty()) std::filesystem::remove(temp_dir_, ec);
}

void ViewerBundling::start(const ViewerBundleSource& source, const BundleParams& params) {
  if (running()) throw Error("bundling: a job is running (cancel it first)");
  validateBundleParams(params);
  if (temp_dir_.empty()) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("fibscope-bundled-" + std::to_string(::getpid()));
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) fail(dir.string(), "cannot create the bundled models' folder: " + ec.message());
    temp_dir_ = dir.string();
  }
  {
    std::lock_guard lock(mutex_);
    progress_.reset();
    result_.reset();
    error_.clear();
    reports_ = 0;
  }
  done_ = false;
  cancel_ = false;
  ++jobs_;
  worker_ = std::thread([this, source, params] { run(source, params); });
}

std::optional<ProgressSnapshot> ViewerBundling::progress() const {
  std::lock_guard lock(mutex_);
  return progress_;
}

std::optional<ViewerBundleResult> ViewerBundling::poll() {
  if (!worker_.joinable() || !done_) return std::nullopt;
  worker_.join();
  std::lock_guard lock(mutex_);
  progress_.reset();
  if (!error_.empty()) throw Error(error_);
  std::optional<ViewerBundleResult> result = std::move(result_);
  result_.reset();
  return result;
}

void ViewerBundling::cancel() {
  cancel_ = true;
  if (worker_.joinable()) worker_.join();
  std::lock_guard lock(mutex_);
  progress_.reset();
  result_.reset();
  error_.clear();
}

void ViewerBundling::report(const ProgressSnapshot& snapshot) {
  std::lock_guard lock(mutex_);
  progress_ = snapshot;
  ++reports_;
}

void ViewerBundling::run(ViewerBundleSource source, BundleParams params) {
  const auto start = std::chrono::steady_clock::now();
  const std::string name = source.name.empty() ? "model" : source.name;
  const Progress::Sink sink = [this](const ProgressSnapshot& s) { report(s); };
  auto stopIfCancelled = [&] {
    if (cancel_.load(std::memory_order_relaxed)) fail(name, "bundling cancelled");
  };
  try {
    {
      ProgressSnapshot reading;
      reading.label = "reading";
      report(reading);
    }
    std::unique_ptr<TractogramReader> reader;
    if (!source.source_path.empty()) {
      reader = openInput(source.source_path);
    } else if (!source.fbl_path.empty()) {
      reader = openFbl(source.fbl_path);
    } else {
      PhantomOptions phantom;
      phantom.streamlines = source.phantom_streamlines;
      phantom.seed = source.phantom_seed;
      reader = openPhantom(phantom);
    }
    const TractogramHeader header = reader->header();
    const Tractogram model = readAllStreamlines(*reader);
    stopIfCancelled();
    BundleSetup setup;
    try {
      setup = planBundling(model, params);
    } catch (const Error& e) {
      fail(name, e.what());
    }

    // A context of its own: the viewer's is the main thread's.
    gpu::ContextOptions context_options;
    context_options.device_name = device_name_;
    context_options.instance.validation = validation_log_ != nullptr;
    context_options.instance.log = validation_log_;
    const gpu::VulkanContext context(context_options);
    Progress progress("bundling", double(params.iterations), "iterations", /*terminal=*/false, sink);
    std::vector<float> moved;
    {
      GpuBundler bundler(context);
      bundler.load(model, setup, params);
      for (uint32_t it = 0; it < params.iterations; ++it) {
        stopIfCancelled();
        bundler.iterate(bundleRadius(params, it));
        progress.set(double(it + 1));
      }
      moved = bundler.finish(model);
    }
    progress.finish();
    stopIfCancelled();

    Tractogram bundled = model;
    bundled.positions = std::move(moved);
    ViewerBundleResult result;
    result.model = name;
    const std::string stem = (std::filesystem::path(temp_dir_) / bundledFileName(name, jobs_)).string();
    result.exact_path = stem + ".tck";
    result.path = stem + ".fbl";
    {
      ProgressSnapshot writing;
      writing.label = "writing";
      report(writing);
    }
    WriterOptions wo;
    wo.overwrite = true;
    writeTractogram(result.exact_path, bundled, header, wo, nullptr);
    {
      std::lock_guard lock(mutex_);
      temp_files_.push_back(result.exact_path);
      temp_files_.push_back(result.path);
    }
    stopIfCancelled();
    ProgressSnapshot compressing;
    compressing.label = "compressing";
    report(compressing);
    // To fiblets here, resampled (bundled fibers have no constant step):
    // the loader then opens the .fbl as it is.
    for (const std::string& w : writeBundledTractogram(result.path, bundled, header, /*overwrite=*/true))
      result.warnings.push_back(w);
    const BundleDisplacement d = bundleDisplacement(model, bundled.positions);
    result.fibers = bundled.streamlineCount();
    result.points = bundled.pointCount();
    result.mean_mm = d.mean_mm;
    result.max_mm = d.max_mm;
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::lock_guard lock(mutex_);
    result.progress_reports = reports_;
    result_ = std::move(result);
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    error_ = cancel_ ? std::string() : std::string(e.what());
    if (error_.empty() && !cancel_) error_ = name + ": bundling failed";
  }
  done_ = true;
}

}  // namespace fibscope
