// The viewer's tubes (issue 15 item 5, issue 16 item 5): the fibers the
// tubes panel asks for (the picked selection, the dissection's kept fibers,
// every fiber of the visible models) as one tube model over every model
// drawn, with scene-global fiber ids (so picking, the selection's highlight
// and every colour mode work on them), drawn as spline tubes (the frame
// renderer's tube stage, tubes/gpu/gpu_tubes.h) or as SVO streamtubes (the
// svo trace stage, svo/gpu/gpu_svo.h), and the tubes' distance field when
// the settings ask for DF AO or DF shadows (gpu_distance_field.h).
//
// A change (other fibers, radius, tolerance, SVO kind or voxel, the
// scene's numbering) builds on a thread of its own, so frames go on: the
// fibers decoded from the models' .fbl (the worker holds each model's
// file, so a model closed meanwhile stays readable until the build ends),
// the tube model (nodes, derivatives, resampling, frames), then the octree
// (voxelising, sorting, building; or read from the octree cache,
// viewer_svo_cache.h) and the distance field on a VulkanContext of the
// worker's own (the viewer's is the main thread's, as ViewerBundling's).
// The finished model, tree and field are uploaded between frames by the
// main thread. What a change leaves as it was is kept: a new distance
// field (DF AO or shadows switched) reuses the drawn tube model and
// octree, another octree the drawn tube model. A change while a build
// runs waits for it and starts the next build then (the last request
// wins; the builds in between are never started); destroying the tubes
// (the viewer quits) cancels a running build at its next step.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/viewer_state.h"
#include "app/viewer/viewer_svo_cache.h"
#include "codec/fbl_file.h"
#include "gpu/vulkan_context.h"
#include "svo/gpu/gpu_distance_field.h"
#include "svo/gpu/gpu_svo.h"
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/tube_model.h"

namespace fibscope {

// One drawn model's fibers to show as tubes.
struct ViewerTubeSource {
  std::shared_ptr<const FblFile> fbl;  // the model's .fbl (read by the worker)
  uint32_t fiber_base = 0;        // its first fiber in the scene drawn
  std::vector<uint32_t> fibers;   // within the model, each once
};

// What the tubes are drawn as, beside the fibers (ViewerTubes::update).
struct ViewerTubeRequest {
  TubesInfo::Svo svo = TubesInfo::Svo::None;
  float voxel_mm = 0;         // the octree's; 0: from the data
  bool distance_field = false;  // the settings run DF AO or DF shadows
  float df_voxel_mm = 0;      // RenderSettings::df_voxel_mm
};

class ViewerTubes {
 public:
  // `device_name`, `validation_log`: the worker's context's, as
  // ViewerBundling's. `cache_dir`: the octree cache's ("": the .fbl
  // cache's directory).
  explicit ViewerTubes(const gpu::VulkanContext& context, std::string device_name = {},
                       std::shared_ptr<gpu::DebugLog> validation_log = {}, std::string cache_dir = {});
  ~ViewerTubes();  // cancels a running build and waits for it; frees the buffers (the caller keeps the device idle)
  ViewerTubes(const ViewerTubes&) = delete;
  ViewerTubes& operator=(const ViewerTubes&) = delete;

  // The buffers the renderers' stages read (the same objects for the
  // viewer's life; empty: not drawn): the spline tubes' (empty while the
  // tubes are drawn from the octree), the segments the octree's lists
  // index, the octree, the distance field.
  const GpuTubes* gpu() const { return &spline_; }
  const GpuTubes* svoSegments() const { return &tubes_; }
  const GpuSvo* svo() const { return &svo_; }
  const GpuDistanceField* field() const { return &field_; }

  // Between frames, nothing in flight. `key` names what `sources` would
  // return (fibers, bases, radius, tolerance) and `request`: when it
  // differs from the last request, sources() is called (on this thread;
  // it only lists fibers) and a build starts (or waits for the running
  // one). Uploads a finished build. Fills info's build fields, progress
  // and message; Error of a decode or build goes to info.message (the
  // tubes then are none). Returns true when the drawn tubes changed.
  // Warnings (a damaged cache entry) go to `warnings`.
  bool update(const std::string& key, const std::function<std::vector<ViewerTubeSource>()>& sources,
              const ViewerTubeRequest& request, TubesInfo& info, std::vector<std::string>* warnings = nullptr);

 private:
  // What the tubes are made of (TubesInfo's radius and tolerance).
  struct ModelOptions {
    float radius_mm = 0, radius_min = 0, radius_max = 0, tolerance_mm = 0;
    std::string radius_from;
  };
  // A tube model with what its octree's cache key needs.
  struct ModelPart {
    TubeModel model;
    TubeBuildStats stats;
    double seconds = 0;
    std::vector<std::string> model_texts;  // svoCacheModelText per source (the cache on)
    std::string radius_text;                // the radius as the cache key names it
  };
  // A request waiting for the worker. `model` (not null): the drawn model,
  // which the request leaves as it is (no decoding, no model build);
  // `keep_svo`: the drawn octree too (only the field is new).
  struct Job {
    std::string key;
    std::string model_key, svo_key;  // the key's parts: the model's, the model's and the octree's
    std::vector<ViewerTubeSource> sources;
    ModelOptions options;
    ViewerTubeRequest request;
    std::shared_ptr<const ModelPart> model;
    bool keep_svo = false;
  };
  struct Built {
    std::string key, model_key, svo_key;
    std::shared_ptr<const ModelPart> model;
    bool model_kept = false, svo_kept = false;  // drawn already: not uploaded again
    std::optional<SvoTree> tree;
    SvoGpuBuildStats svo_stats;
    bool svo_from_cache = false;
    double svo_seconds = 0;
    std::vector<float> field;  // the distance field's values, downloaded from the worker's device
    DistanceFieldGrid field_grid;
    double field_seconds = 0;
    std::vector<std::string> warnings;
    std::string error;
  };
  struct Shared {  // between the worker and update()
    std::mutex mutex;
    std::optional<ProgressSnapshot> progress;
    std::atomic<bool> cancel{false};  // the destructor's: the worker stops at its next step
    void report(const ProgressSnapshot& s);
    // Throws Error once `cancel` holds (the worker's steps call it).
    void throwIfCancelled() const;
    // A step without a count: `label` reported, after throwIfCancelled.
    void phase(const char* label);
  };
  // Reports to shared_ (a progress bar's sink for the builds' Progress).
  Progress::Sink progressSink() const {
    return [shared = shared_](const ProgressSnapshot& s) { shared->report(s); };
  }
  // The job's tube model: its fibers decoded and built (on the worker).
  std::shared_ptr<const ModelPart> buildModel(const Job& job);
  void start(Job job);
  // The octree and the field of `b.model` on the worker's context.
  void buildOnDevice(const Job& job, Built& b);
  void upload(Built& built, TubesInfo& info);
  void clear();
  void clearField();

  const gpu::VulkanContext& context_;
  std::string device_name_;
  std::shared_ptr<gpu::DebugLog> validation_log_;
  std::unique_ptr<gpu::VulkanContext> worker_context_;  // made by the first build that needs it, used by the worker only
  SvoCache cache_;
  GpuTubes tubes_;   // owned: the model's nodes and segments
  GpuTubes spline_;  // a view of tubes_ (not owned) while drawn as spline tubes, else empty
  GpuSvo svo_;
  GpuDistanceField field_;
  std::shared_ptr<Shared> shared_ = std::make_shared<Shared>();
  std::string wanted_key_;  // the last request's key
  // What is drawn: its key's parts and model (reused by a request that
  // leaves them as they are).
  std::string drawn_model_key_, drawn_svo_key_;
  std::shared_ptr<const ModelPart> drawn_model_;
  std::optional<Job> pending_;  // waiting for the running build
  std::future<Built> build_;
};

}  // namespace fibscope
