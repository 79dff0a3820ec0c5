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
// scene's numbering) decodes the fibers from the models' .fbl on the
// calling thread (the CPU decoder: ~10^7 points in a fraction of a second)
// and builds on a thread of its own, so frames go on: the tube model
// (nodes, derivatives, resampling, frames), then the octree (voxelising,
// sorting, building; or read from the octree cache, viewer_svo_cache.h)
// and the distance field on a VulkanContext of the worker's own (the
// viewer's is the main thread's, as ViewerBundling's). The finished model,
// tree and field are uploaded between frames by the main thread. A change
// while a build runs waits for it and starts the next build then (the
// last request wins; the builds in between are never started).
#pragma once

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
  const FblFile* fbl = nullptr;   // the model's .fbl (read during update only)
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
  ~ViewerTubes();  // waits for a running build; frees the buffers (the caller keeps the device idle)
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
  // differs from the last request, sources() is called and a build starts
  // (or waits for the running one). Uploads a finished build. Fills info's
  // build fields, progress and message; Error of a decode or build goes to
  // info.message (the tubes then are none). Returns true when the drawn
  // tubes changed. Warnings (a damaged cache entry) go to `warnings`.
  bool update(const std::string& key, const std::function<std::vector<ViewerTubeSource>()>& sources,
              const ViewerTubeRequest& request, TubesInfo& info, std::vector<std::string>* warnings = nullptr);

 private:
  // A request decoded and waiting for the worker: the fibers' points (in
  // the sources' order), each one's scene-global id, the build's options.
  struct Job {
    std::string key;
    Tractogram fibers;
    std::vector<uint32_t> scene_ids;
    TubeBuildOptions options;
    ViewerTubeRequest request;
    std::optional<SvoCacheKey> svo_key;  // the octree's cache entry (none: the cache is off)
  };
  struct Built {
    std::string key;
    TubeModel model;
    TubeBuildStats stats;
    double seconds = 0;
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
  };
  void start(Job job);
  // The octree and the field of `b.model` on the worker's context.
  void buildOnDevice(const Job& job, Built& b);
  void upload(Built& built, TubesInfo& info);
  void clear();

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
  std::optional<Job> pending_;  // decoded, waiting for the running build
  std::future<Built> build_;
};

}  // namespace fibscope
