// The viewer's model loader: tractograms are read, compressed through the
// .fbl cache, opened and measured on one worker thread, so the window never
// waits for a file.
//
// Jobs run one at a time in the order requested. A job:
//   1. a .fbl input is opened as is; any other file (or the phantom) goes
//      through FblCache: the cached copy when its key still matches, else
//      compressTractogram into the cache, reporting progress;
//   2. FblFile::open + verify (every checksum), codec header checks;
//   3. bounds of every point and ~4096 sample points (to frame the camera),
//      decoding only the fiblets that can reach the box's faces and a
//      spread of fiblets for the sample, not the whole file;
//   4. statistics.
// Bad input never stops the worker: every exception becomes a one-line error
// in the job's LoadEvent (fibscope::Error's text, which names the file;
// std::bad_alloc and other exceptions are prefixed with the path).
//
// No Vulkan here: the caller uploads on the main thread
// (GpuDataset::upload(context, model->fbl)), because the VulkanContext is
// used by the main thread only.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "codec/compressor.h"
#include "codec/fbl_file.h"
#include "core/progress.h"
#include "render/camera.h"

namespace fibscope {

class FblCache;

struct ModelLoaderOptions {
  uint64_t phantom_streamlines = 10000;  // the built-in phantom (request(""))
  uint64_t phantom_seed = 1;
  size_t sample_points = 4096;
  bool use_cache = true;      // false: compress into an unlinked temporary file every time
  std::string cache_dir;      // "" = defaultFblCacheDir()
  uint64_t cache_max_bytes = 0;  // 0 = defaultFblCacheMaxBytes()
  // Compression options (terminal_progress and progress_sink are replaced
  // by the loader's own progress).
  CompressOptions compress;
};

struct ModelData {
  std::string name;         // file name without directories, or "phantom (N fibers)"
  std::string source_path;  // as requested; "" for the phantom
  FblFile fbl;              // opened and verified; what GpuDataset::upload takes
  Bounds bounds;            // of every point, world mm
  std::vector<Vec3d> sample;  // ~sample_points points spread over the file (snugCamera)
  // Statistics.
  uint64_t streamlines = 0, points = 0, segments = 0, fiblets = 0;
  double step_mm = 0;         // the codec's step
  uint64_t input_bytes = 0;   // the input file (0 for the phantom)
  uint64_t fbl_bytes = 0;     // the whole .fbl
  bool from_cache = false;    // true: no compression ran (a cached copy, or a .fbl input)
  bool temporary = false;     // the cache was not writable: the copy lives only while mapped
  double seconds = 0;         // the whole job, request to ready
  double compress_seconds = 0;  // 0 when from_cache
  double mean_error_um = 0, max_error_um = 0;  // codec error when compressed now (0 from cache)
  std::vector<std::string> warnings;  // reader, compressor and cache warnings
  // input / .fbl bytes; 0 when the input size is unknown (phantom).
  double compressionRatio() const { return fbl_bytes && input_bytes ? double(input_bytes) / double(fbl_bytes) : 0.0; }
};

struct LoadEvent {
  uint64_t id = 0;
  std::string path;                  // as requested ("" = phantom)
  std::unique_ptr<ModelData> model;  // null on error or cancellation
  std::string error;                 // one line when model is null
  bool cancelled = false;
  bool ok() const { return model != nullptr; }
};

// The running job's progress: the current phase's label ("analysing",
// "compressing", "opening", "measuring"), done/total, rate and ETA.
struct LoadProgress {
  uint64_t id = 0;
  std::string path;
  ProgressSnapshot snapshot;
};

class ModelLoader {
 public:
  explicit ModelLoader(ModelLoaderOptions options = {});
  // Cancels the running job, drops the queued ones and joins the worker.
  ~ModelLoader();
  ModelLoader(const ModelLoader&) = delete;
  ModelLoader& operator=(const ModelLoader&) = delete;

  // Queues a load; "" = the built-in phantom. Returns the job id (> 0).
  uint64_t request(std::string path);
  // Finished jobs since the last poll, in completion order. Never blocks.
  std::vector<LoadEvent> poll();
  // Blocks until a job finishes or `timeout_seconds` pass (tests, scripts).
  std::optional<LoadEvent> wait(double timeout_seconds);
  // The running job's progress (empty when idle).
  std::vector<LoadProgress> progress() const;
  // Jobs queued or running.
  size_t pending() const;
  bool busy() const { return pending() > 0; }

  // A queued job is dropped, the running one stops at its next chunk of
  // input (compression checks the flag between reads; opening and measuring
  // a .fbl are short and finish). Either way its LoadEvent has cancelled.
  void cancel(uint64_t id);
  void cancelAll();

  const ModelLoaderOptions& options() const { return options_; }

 private:
  struct Job {
    uint64_t id = 0;
    std::string path;
  };
  void run();
  LoadEvent load(const Job& job, const std::atomic<bool>& cancel);

  ModelLoaderOptions options_;
  std::unique_ptr<FblCache> cache_;  // one for the loader's life (warns once when unwritable)
  mutable std::mutex mutex_;
  std::condition_variable wake_;      // worker: a job queued or stop
  std::condition_variable finished_;  // wait(): an event
  std::deque<Job> queue_;
  std::vector<LoadEvent> events_;
  std::optional<Job> running_;
  std::shared_ptr<std::atomic<bool>> cancel_running_;  // the running job's flag
  ProgressSnapshot running_progress_;
  bool has_progress_ = false;
  uint64_t next_id_ = 1;
  bool stop_ = false;
  std::thread worker_;  // last: started after every member above exists
};

// The job's work without a thread (the loader's worker calls it): loads
// `path` ("" = phantom) as described above. Throws Error on failure; a set
// `cancel` flag throws Error("<path>: cancelled"). `progress_sink` receives
// the snapshots. `cache` null: a cache from the options (or none when
// !use_cache).
ModelData loadModel(const std::string& path, const ModelLoaderOptions& options,
                    const std::atomic<bool>* cancel = nullptr, const Progress::Sink& progress_sink = {},
                    FblCache* cache = nullptr);

// Bounds of every point and about `sample_count` sample points of an opened
// .fbl, in world mm (decodes the fiblets near the box's faces and a spread
// of fiblets, not the whole file). Throws Error naming the file for a bad
// codec header.
void fblBoundsAndSample(const FblFile& file, size_t sample_count, Bounds& bounds, std::vector<Vec3d>& sample);

}  // namespace fibscope
