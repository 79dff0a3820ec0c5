// The viewer's fiber selection on the GPU side: the FiberSelection of the
// model being drawn, its bit words in a GpuFiberAttributes buffer for the
// highlight (GpuScene::selection_bits), the lengths of the selected fibers
// for the selection panel, and the export of the selection to a .tck.
//
// Fiber ids are the G-buffer's, so a selection belongs to one dataset: when
// the drawn model changes (another model made active, a model reloaded or
// closed) the selection is cleared. Every call that touches the GPU (sync)
// runs between frames, after the frame's fence.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <string>

#include "app/viewer/viewer_state.h"
#include "codec/fbl_file.h"
#include "gpu/vulkan_context.h"
#include "render/fiber_selection.h"
#include "render/gpu_dataset.h"
#include "render/gpu_fiber_attributes.h"
#include "render/gpu_pick.h"

namespace fibscope {

// The model a selection refers to.
struct SelectionSource {
  const GpuDataset* dataset = nullptr;  // null: no model (the selection is cleared)
  // The model's opened .fbl (export, lengths); null when not in reach.
  const FblFile* fbl = nullptr;
  // The model's file: when `fbl` is null and this is a .fbl, it is opened
  // here (once per model) for export and lengths.
  std::string path;
};

class ViewerSelection {
 public:
  explicit ViewerSelection(const gpu::VulkanContext& context) : context_(&context) {}

  // Between frames (no frame in flight): follows `source` (a different
  // dataset than the last one clears the selection and its buffer), uploads
  // the bit words when the selection changed since the last upload, and
  // refreshes `info` (the panel's list with lengths). Errors from the GPU
  // (memory) propagate as Error.
  void sync(const SelectionSource& source, SelectionInfo& info);

  // For GpuScene::selection_bits of the synced dataset's frames: 0 when
  // nothing is selected (nothing dimmed).
  VkDeviceAddress bits() const { return attributes_ ? attributes_->selection() : 0; }
  // The dataset of the last sync (what picks refer to).
  const GpuDataset* dataset() const { return dataset_; }

  // A click: a plain one selects the hit fiber (the background clears the
  // selection), an added one (ctrl) toggles the hit fiber (the background
  // changes nothing).
  void pick(const PickResult& result, bool add);
  void clear() { selection_.clear(); }
  size_t size() const { return selection_.size(); }
  const FiberSelection& selection() const { return selection_; }

  // Writes the selected fibers (in selection order) to `tck_path` from the
  // model's .fbl. Throws Error (one line) when nothing is selected, the
  // .fbl is not in reach, or exportFibers fails.
  void exportTck(const std::string& tck_path) const;

 private:
  const FblFile* fbl() const;
  std::optional<float> lengthMm(uint32_t fiber) const;

  const gpu::VulkanContext* context_;
  FiberSelection selection_;
  const GpuDataset* dataset_ = nullptr;
  VkDeviceAddress dataset_address_ = 0;  // with the pointer: a reloaded model at a reused address is still new
  uint64_t fiber_count_ = 0;
  std::optional<GpuFiberAttributes> attributes_;
  std::optional<uint64_t> uploaded_revision_;
  std::optional<uint64_t> listed_revision_;
  const FblFile* source_fbl_ = nullptr;
  std::string opened_path_;             // the .fbl opened from SelectionSource::path
  std::optional<FblFile> opened_fbl_;   // null when it could not be opened
  std::string fbl_error_;               // why the .fbl is not in reach
};

}  // namespace fibscope
