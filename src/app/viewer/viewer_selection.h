// The viewer's fiber selection on the GPU side: fibers of any loaded model
// as (model, fiber) pairs, their bits in a GpuFiberAttributes buffer for
// the highlight (GpuScene::selection_bits, over the scene-global fiber ids
// of the models drawn), the lengths of the selected fibers for the
// selection panel, and the export of the selection to a .tck.
//
// Several models are drawn in one frame with scene-global fiber ids
// (render/gpu/scene_table.h), so a selection entry names its model by the
// viewer's model id (unique per load: a reloaded file is a new model) and
// the fiber within it. A closed model takes its entries with it; a hidden
// one keeps them (not highlighted while hidden). Every call that touches
// the GPU (sync) runs between frames, after the frame's fence.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "app/viewer/viewer_state.h"
#include "codec/fbl_file.h"
#include "gpu/vulkan_context.h"
#include "render/gpu/dataset.h"
#include "render/gpu/fiber_attributes.h"

namespace fibscope {

// A model the selection may refer to.
struct SelectionModel {
  uint64_t id = 0;  // the viewer's model id
  std::string name;
  const GpuDataset* dataset = nullptr;
  // The model's opened .fbl (export, lengths); null when not in reach.
  const FblFile* fbl = nullptr;
  // The model's file: when `fbl` is null and this is a .fbl, it is opened
  // here (once per model) for export and lengths.
  std::string path;
  // Its first fiber in the scene the next frames draw; nullopt: not drawn
  // (hidden).
  std::optional<uint32_t> fiber_base;
};

struct SelectedEntry {
  uint64_t model = 0;  // SelectionModel::id
  uint32_t fiber = 0;  // within the model
  bool operator==(const SelectedEntry&) const = default;
};

class ViewerSelection {
 public:
  explicit ViewerSelection(const gpu::VulkanContext& context) : context_(&context) {}

  // Between frames (no frame in flight): follows the loaded `models` (the
  // entries of a model no longer listed are dropped), uploads the bit
  // words over `scene_fibers` scene-global fibers when the selection or the
  // drawn scene changed since the last upload, and refreshes `info` (the
  // panel's list with model names and lengths). `active` (an id, or 0)
  // picks the model an export writes. Errors from the GPU (memory)
  // propagate as Error.
  void sync(std::span<const SelectionModel> models, uint32_t scene_fibers, uint64_t active, SelectionInfo& info);

  // For GpuScene::selection_bits of the synced scene's frames: 0 when no
  // drawn fiber is selected (nothing dimmed).
  VkDeviceAddress bits() const { return attributes_ ? attributes_->selection() : 0; }

  // A click on fiber `fiber` of model `model` (nullopt: the background): a
  // plain one selects the fiber (the background clears the selection), an
  // added one (ctrl) toggles it (the background changes nothing).
  void pick(std::optional<SelectedEntry> hit, bool add);
  void clear();
  size_t size() const { return entries_.size(); }
  const std::vector<SelectedEntry>& entries() const { return entries_; }  // in selection order
  uint64_t revision() const { return revision_; }  // changes with every change of entries()

  // Writes the selected fibers of ONE model (in selection order) to
  // `tck_path` from its .fbl: the active model's when it has selected
  // fibers, else the model of the fiber selected last (the models' points
  // may not share a space or header, so no file mixes them). Returns that
  // model's name and how many selected fibers of other models were left
  // out. Throws Error (one line) when nothing is selected, the .fbl is not
  // in reach, or exportFibers fails.
  struct Exported {
    std::string model;
    size_t written = 0, left_out = 0;
  };
  Exported exportTck(const std::string& tck_path) const;

 private:
  // Per model: its source, and the .fbl opened from its path when needed.
  struct Known {
    SelectionModel source;
    std::optional<FblFile> opened;  // from source.path
    std::string fbl_error;          // why the .fbl is not in reach
    const FblFile* fbl() const { return source.fbl ? source.fbl : (opened ? &*opened : nullptr); }
  };
  std::optional<float> lengthMm(const Known& model, uint32_t fiber) const;

  const gpu::VulkanContext* context_;
  std::vector<SelectedEntry> entries_;
  uint64_t revision_ = 1;  // changes with every modification
  std::map<uint64_t, Known> models_;
  uint64_t active_ = 0;
  std::optional<GpuFiberAttributes> attributes_;
  // What the uploaded bits describe: the revision and each drawn model's
  // base; and what the panel lists.
  std::optional<uint64_t> uploaded_revision_;
  std::vector<std::pair<uint64_t, uint32_t>> uploaded_bases_;
  uint32_t uploaded_fibers_ = 0;
  std::optional<uint64_t> listed_revision_;
};

}  // namespace fibscope
