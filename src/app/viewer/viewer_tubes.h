// The viewer's spline tubes (issue 15 item 5): the fibers the tubes panel
// asks for (the picked selection, the dissection's kept fibers) as one
// tube model over every model drawn, with scene-global fiber ids (so
// picking, the selection's highlight and every colour mode work on them),
// uploaded for the frame renderer's tube stage (tubes/gpu/gpu_tubes.h).
//
// A change (other fibers, radius, tolerance, the scene's numbering) decodes
// the fibers from the models' .fbl on the calling thread (the CPU decoder:
// ~10^7 points in a fraction of a second) and builds the model (nodes,
// derivatives, resampling, frames: the heavy part) on a thread of its own,
// so frames go on; the finished model is uploaded between frames. A change
// while a build runs waits for it and starts the next build then (the
// last request wins; the builds in between are never started).
#pragma once

#include <cstdint>
#include <functional>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/viewer_state.h"
#include "codec/fbl_file.h"
#include "gpu/vulkan_context.h"
#include "tubes/gpu/gpu_tubes.h"
#include "tubes/tube_model.h"

namespace fibscope {

// One drawn model's fibers to show as tubes.
struct ViewerTubeSource {
  const FblFile* fbl = nullptr;   // the model's .fbl (read during update only)
  uint32_t fiber_base = 0;        // its first fiber in the scene drawn
  std::vector<uint32_t> fibers;   // within the model, each once
};

class ViewerTubes {
 public:
  explicit ViewerTubes(const gpu::VulkanContext& context) : context_(context) {}
  ~ViewerTubes();  // waits for a running build; frees the buffers (the caller keeps the device idle)
  ViewerTubes(const ViewerTubes&) = delete;
  ViewerTubes& operator=(const ViewerTubes&) = delete;

  // The buffers the renderers' tube stage reads (the same object for the
  // viewer's life; empty: no tubes drawn).
  const GpuTubes* gpu() const { return &tubes_; }

  // Between frames, nothing in flight. `key` names what `sources` would
  // return (fibers, bases, radius, tolerance): when it differs from the
  // last request, sources() is called and a build starts (or waits for
  // the running one). Uploads a finished build. Fills info's build fields
  // and message; Error of a decode or build goes to info.message (the
  // tubes then are none). Returns true when the drawn tubes changed.
  bool update(const std::string& key, const std::function<std::vector<ViewerTubeSource>()>& sources,
              TubesInfo& info);

 private:
  // A request decoded and waiting for the worker: the fibers' points (in
  // the sources' order), each one's scene-global id, the build's options.
  struct Job {
    std::string key;
    Tractogram fibers;
    std::vector<uint32_t> scene_ids;
    TubeBuildOptions options;
  };
  struct Built {
    std::string key;
    TubeModel model;
    TubeBuildStats stats;
    double seconds = 0;
    std::string error;
  };
  void start(Job job);
  void upload(Built& built, TubesInfo& info);

  const gpu::VulkanContext& context_;
  GpuTubes tubes_;
  std::string wanted_key_;  // the last request's key
  std::optional<Job> pending_;  // decoded, waiting for the running build
  std::future<Built> build_;
};

}  // namespace fibscope
