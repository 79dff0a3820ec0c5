// The viewer's Bundle action (issue 17 item 1): bundling of a loaded model
// on a worker thread of its own, never on the frame loop.
//
// The worker reads the model's fibers (its source file, or its .fbl, or the
// loader's phantom made again), plans the grid (bundle_setup.h) and runs
// GpuBundler on a VulkanContext of its own: the viewer's context is used by
// the main thread only (model_loader.h), and a second context needs no
// locking of queues shared with the frame loop. The bundled copy is written
// to a temporary .tck (its exact positions, for Save) and compressed to a
// temporary .fbl (resampled, as `fibscope bundle OUT.fbl`), both removed
// with the ViewerBundling; the frame loop then opens the .fbl through the
// ModelLoader, so it is uploaded and listed like any model.
//
// Cancel (or the destructor) stops the job at its next iteration and joins
// the worker; the job's context and buffers are released on the worker.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bundling/bundle_params.h"
#include "core/progress.h"
#include "gpu/vulkan_instance.h"

namespace fibscope {

// Where the job reads the model's fibers: `source_path` when set (the
// tractogram as given, exact), else `fbl_path`, else the phantom.
struct ViewerBundleSource {
  std::string name;  // the model's name, for the bundled copy's file name and messages
  std::string source_path, fbl_path;
  uint64_t phantom_streamlines = 10000, phantom_seed = 1;
};

struct ViewerBundleResult {
  std::string model;  // the source model's name
  std::string path;        // the bundled copy compressed to fiblets (a temporary .fbl, resampled)
  std::string exact_path;  // its exact positions (a temporary .tck): what Save writes
  std::vector<std::string> warnings;
  uint64_t fibers = 0, points = 0;
  double mean_mm = 0, max_mm = 0;  // displacement of the points
  double seconds = 0;
  uint64_t progress_reports = 0;  // snapshots the progress bar received
};

class ViewerBundling {
 public:
  // `device_name`: as the viewer's --device (empty: the best device).
  // `validation_log`: non-null with the viewer's --validate: the worker's
  // context turns the validation layers on and files their messages there,
  // so the viewer's end-of-run check counts them with its own.
  explicit ViewerBundling(std::string device_name = {}, std::shared_ptr<gpu::DebugLog> validation_log = {});
  // Cancels a running job, joins the worker, removes the temporary files.
  ~ViewerBundling();
  ViewerBundling(const ViewerBundling&) = delete;
  ViewerBundling& operator=(const ViewerBundling&) = delete;

  // Starts a job. Throws Error (one line) for invalid parameters or while
  // a job runs.
  void start(const ViewerBundleSource& source, const BundleParams& params);
  // A job started and not yet polled as finished.
  bool running() const { return worker_.joinable(); }
  // The running job's progress (label "reading", "bundling", "writing").
  std::optional<ProgressSnapshot> progress() const;
  // The finished job's result; Error with its one-line message when it
  // failed; nothing while it runs or when none ran. Never blocks.
  std::optional<ViewerBundleResult> poll();
  // Stops the running job at its next iteration and joins (poll then
  // reports nothing).
  void cancel();

 private:
  void run(ViewerBundleSource source, BundleParams params);
  void report(const ProgressSnapshot& snapshot);

  std::string device_name_;
  std::shared_ptr<gpu::DebugLog> validation_log_;
  std::string temp_dir_;  // created at the first job
  std::vector<std::string> temp_files_;
  uint64_t jobs_ = 0;
  mutable std::mutex mutex_;
  std::optional<ProgressSnapshot> progress_;
  std::optional<ViewerBundleResult> result_;
  std::string error_;
  uint64_t reports_ = 0;
  std::atomic<bool> done_{false};
  std::atomic<bool> cancel_{false};
  std::thread worker_;
};

}  // namespace fibscope
