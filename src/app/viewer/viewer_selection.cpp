#include "app/viewer/viewer_selection.h"

#include <algorithm>
#include <set>

#include "app/open_input.h"
#include "core/error.h"
#include "gpu/buffer.h"
#include "render/fiber_selection.h"

namespace fibscope {

void ViewerSelection::sync(std::span<const SelectionModel> models, uint32_t scene_fibers, uint64_t active,
                           SelectionInfo& info) {
  // Follow the model list: forget closed models and their entries, open
  // each new model's .fbl from its path once when no opened one is given.
  std::set<uint64_t> listed;
  for (const SelectionModel& m : models) listed.insert(m.id);
  for (auto it = models_.begin(); it != models_.end();) {
    if (listed.count(it->first) == 0) it = models_.erase(it);
    else ++it;
  }
  const size_t before = entries_.size();
  std::erase_if(entries_, [&](const SelectedEntry& e) { return listed.count(e.model) == 0; });
  if (entries_.size() != before) ++revision_;
  for (const SelectionModel& m : models) {
    auto [it, fresh] = models_.try_emplace(m.id);
    Known& known = it->second;
    const bool new_path = fresh || known.source.path != m.path;
    known.source = m;
    if (m.fbl || !new_path) continue;
    known.opened.reset();
    known.fbl_error.clear();
    if (m.path.empty() || !isFblPath(m.path)) {
      known.fbl_error = "the .fbl of " + m.name + " is not available yet";
    } else {
      try {
        known.opened = FblFile::open(m.path);
      } catch (const Error& e) {
        known.fbl_error = e.what();
      }
    }
  }
  active_ = active;

  // The bits over the scene's global fibers: model m's fiber f is bit
  // base_m + f, for the models drawn.
  std::vector<std::pair<uint64_t, uint32_t>> bases;
  for (const SelectionModel& m : models)
    if (m.fiber_base && m.dataset) bases.push_back({m.id, *m.fiber_base});
  if (uploaded_revision_ != revision_ || bases != uploaded_bases_ || scene_fibers != uploaded_fibers_) {
    std::vector<uint32_t> words;
    bool any = false;
    for (const SelectedEntry& e : entries_) {
      const Known& known = models_.at(e.model);
      if (!known.source.fiber_base || !known.source.dataset || e.fiber >= known.source.dataset->block().fiber_count)
        continue;
      const uint64_t global = uint64_t(*known.source.fiber_base) + e.fiber;
      if (global >= scene_fibers) continue;
      if (words.empty()) words.assign(selectionWordCount(scene_fibers), 0u);
      words[global / 32] |= 1u << (global % 32);
      any = true;
    }
    if (!any) {
      if (attributes_) attributes_->clearSelection();  // address 0: nothing dimmed, no upload needed
    } else {
      if (!attributes_ || attributes_->fiberCount() != scene_fibers) {
        attributes_.reset();  // the frame that read the old buffer has completed (no frame in flight)
        attributes_.emplace(*context_, scene_fibers);
      }
      attributes_->uploadSelection(words);
    }
    uploaded_revision_ = revision_;
    uploaded_bases_ = std::move(bases);
    uploaded_fibers_ = scene_fibers;
  }

  bool exportable = false;
  for (const SelectedEntry& e : entries_) exportable |= models_.at(e.model).fbl() != nullptr;
  if (listed_revision_ != revision_ || info.exportable != exportable) {
    info.fibers.clear();
    for (const SelectedEntry& e : entries_) {
      const Known& known = models_.at(e.model);
      info.fibers.push_back({known.source.name, e.fiber, lengthMm(known, e.fiber)});
    }
    info.exportable = exportable;
    listed_revision_ = revision_;
  }
}

void ViewerSelection::pick(std::optional<SelectedEntry> hit, bool add) {
  if (hit && models_.count(hit->model) == 0) hit.reset();  // not a model of the last sync
  if (!hit) {
    if (!add) clear();
    return;
  }
  const auto at = std::find(entries_.begin(), entries_.end(), *hit);
  if (add) {
    if (at != entries_.end()) entries_.erase(at);
    else entries_.push_back(*hit);
  } else {
    if (entries_.size() == 1 && at != entries_.end()) return;  // already exactly this one
    entries_.assign(1, *hit);
  }
  ++revision_;
}

void ViewerSelection::clear() {
  if (entries_.empty()) return;
  entries_.clear();
  ++revision_;
}

// The .fbl's "fiber_length_mm" when in reach, else the dataset's length
// buffer on the GPU (the same values: both are the lengths the codec
// measured), one float copied back per fiber.
std::optional<float> ViewerSelection::lengthMm(const Known& model, uint32_t fiber) const {
  try {
    if (const FblFile* file = model.fbl()) {
      if (std::optional<float> length = fiberLengthMm(*file, fiber)) return length;
    }
    const GpuDataset* dataset = model.source.dataset;
    if (dataset && fiber < dataset->block().fiber_count) {
      const gpu::Buffer& lengths = dataset->fiberLength();
      const VkDeviceSize offset = VkDeviceSize(fiber) * sizeof(float);
      if (lengths.buffer != VK_NULL_HANDLE && offset + sizeof(float) <= lengths.size) {
        float length = 0;
        gpu::downloadFromBuffer(*context_, lengths, &length, sizeof(float), offset);
        return length;
      }
    }
  } catch (const Error&) {
    // A length the panel cannot show is not worth more than a blank cell.
  }
  return std::nullopt;
}

ViewerSelection::Exported ViewerSelection::exportTck(const std::string& tck_path) const {
  if (entries_.empty()) throw Error("export-selection: no fiber is selected");
  uint64_t model = entries_.back().model;
  for (const SelectedEntry& e : entries_)
    if (e.model == active_) model = active_;
  const Known& known = models_.at(model);
  const FblFile* file = known.fbl();
  if (!file)
    throw Error("export-selection: " + (known.fbl_error.empty() ? "the .fbl of " + known.source.name + " is not in reach"
                                                                : known.fbl_error));
  std::vector<uint32_t> fibers;
  for (const SelectedEntry& e : entries_)
    if (e.model == model) fibers.push_back(e.fiber);
  exportFibers(*file, fibers, tck_path);
  return Exported{known.source.name, fibers.size(), entries_.size() - fibers.size()};
}

}  // namespace fibscope
