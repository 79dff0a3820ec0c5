// The viewer's virtual dissection on the GPU and on disk: the state's
// criteria (dissection.h) evaluated by GpuFiberFilter on the scene the
// frames draw, its kept bits put into each frame's GpuScene, and the export
// of the kept fibers, which streams the model's source file through
// runFilter as `fibscope filter` does (the same file comes out).
//
// When the filter runs: evaluate() is called between frames; it does GPU
// work only when the criteria or the scene (the datasets drawn, their
// numbering, a baseline's raw vertices) changed since the last update.
// A change of the criteria alone (a ROI dragged, a radius typed) waits
// while it keeps changing when the last update was slow, so a slow device
// never holds every frame of a drag; a change of the scene is evaluated at
// once (the old bits would number other fibers).
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/dissection.h"
#include "codec/fbl_file.h"
#include "gpu/vulkan_context.h"
#include "phantom/phantom.h"
#include "render/gpu/raw_tractogram.h"
#include "render/gpu/scene.h"
#include "render/gpu/scene_table.h"
#include "select/gpu/gpu_fiber_filter.h"

namespace fibscope {

// What the next frame draws, as the filter sees it.
struct DissectionScene {
  const SceneLayout* layout = nullptr;    // the fiblet datasets (compute pipeline)
  const GpuRawTractogram* raw = nullptr;  // a baseline's raw vertices (their streamlines are the fibers), or null
  VkDeviceAddress raw_lengths = 0;        // float per raw streamline (mm)
  float step_size_mm = NAN;               // for the length limits' margin (FiberFilter)
  // The .fbl of each layout entry (raw: of the baseline's model alone), in
  // the entries' order: their "dps/" sections are the per-fiber values of
  // the scalar ranges. Null: a model without arrays.
  std::vector<const FblFile*> files;
};

// The file an export streams: a loaded model's source.
struct DissectionExportSource {
  std::string model;  // its name, for messages
  std::string path;   // "" = the built-in phantom, made again with `phantom`
  PhantomOptions phantom;
};

struct DissectionExportResult {
  std::string path, model;
  uint64_t kept = 0, streamlines = 0;
  size_t groups = 0;  // TRX groups written (one per ROI that holds an exported fiber)
  double seconds = 0;
  std::vector<std::string> warnings;
};

class ViewerDissection {
 public:
  // A change of the criteria alone waits while the last update took longer
  // than kSlowUpdateMs, until they have stayed the same for kSettleMs.
  static constexpr double kSlowUpdateMs = 50;
  static constexpr double kSettleMs = 150;

  explicit ViewerDissection(const gpu::VulkanContext& context) : context_(context) {}
  ~ViewerDissection();  // cancels a running export and waits for it
  ViewerDissection(const ViewerDissection&) = delete;
  ViewerDissection& operator=(const ViewerDissection&) = delete;

  // Between frames (nothing in flight: an update rewrites the bits a frame
  // reads). Updates the kept bits when needed (see above; `now` skips the
  // wait) and fills state.stats. Criteria the GPU filter refuses (too many
  // regions) keep everything and say why in stats.error.
  void evaluate(DissectionState& state, const DissectionScene& scene, bool now);
  // The frame's bits for the scene last evaluated (`baseline`: the raw
  // vertices are drawn): kept_bits (and kept_point_bits) when hiding;
  // dimming, selection_bits (the kept fibers drawn as the selection) and
  // true. False and nothing set without criteria.
  bool apply(const DissectionState& state, GpuScene& scene, bool baseline) const;
  // The scene-global ids of the fibers the last evaluation kept over the
  // fiblet scene (read back from the GPU: between frames); nullopt without
  // criteria, after a failed update or when the bits are a baseline's.
  std::optional<std::vector<uint32_t>> keptSceneFibers(const DissectionState& state) const;
  // Changes whenever the kept bits may have (the scene or the criteria
  // they were evaluated for).
  std::string keptKey() const { return scene_key_ + "|" + criteria_key_ + (failed_ ? "|failed" : ""); }

  // Starts writing the fibers the state's criteria keep of `source` to
  // `path` (.tck, .trk, .trx; replaced if it exists) on a thread of its
  // own; a TRX output gets a group per ROI (see viewer_dissection.cpp).
  // Throws Error when an export runs already.
  void startExport(const DissectionState& state, const DissectionExportSource& source, const std::string& path);
  bool exporting() const { return export_.valid(); }
  // The finished export's result, or nullopt while none has finished.
  // Throws the export's Error (one line) once.
  std::optional<DissectionExportResult> pollExport();

 private:
  GpuFiberFilter& filter(std::unique_ptr<GpuFiberFilter>& f);

  const gpu::VulkanContext& context_;
  std::unique_ptr<GpuFiberFilter> fiblets_, raw_;  // made at the first criteria
  // What the bits are of: the scene and the criteria (keys), and when the
  // criteria were last seen to change.
  std::string scene_key_, criteria_key_, pending_key_;
  // The scalar ranges' values over the scene (scalars[r][global fiber]) and
  // the arrays listed for the panel, for the scene and ranges of the key.
  std::vector<std::vector<float>> scalars_;
  std::string scalars_key_, arrays_key_;
  std::chrono::steady_clock::time_point pending_since_;
  bool raw_scene_ = false;  // the bits are the raw filter's
  bool failed_ = false;     // the last update threw: nothing is filtered
  double last_update_ms_ = 0;
  std::shared_ptr<std::atomic<bool>> cancel_export_;
  std::future<DissectionExportResult> export_;
};

// The per-streamline arrays of a .fbl (its "dps/" sections; values empty).
std::vector<DataArray> fblPerStreamlineArrays(const FblFile& file);

// The export's work without a thread (tests, the thread): the kept fibers
// of `source` under `state`'s criteria to `path`, as runFilter writes them
// (FiberFilter with the source header's step size, the source's header for
// the writer), with the ROI groups for a TRX output. Throws Error.
DissectionExportResult exportKeptFibers(const RoiSet& set, const DissectionExportSource& source,
                                        const std::string& path, const std::atomic<bool>* cancel = nullptr);

}  // namespace fibscope
