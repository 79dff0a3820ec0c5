#include "app/viewer/viewer_selection.h"

#include <vector>

#include "app/open_input.h"
#include "core/error.h"
#include "gpu/buffer.h"

namespace fibscope {

void ViewerSelection::sync(const SelectionSource& source, SelectionInfo& info) {
  const VkDeviceAddress address = source.dataset ? source.dataset->blockAddress() : 0;
  const uint64_t fibers = source.dataset ? source.dataset->block().fiber_count : 0;
  if (source.dataset != dataset_ || address != dataset_address_ || fibers != fiber_count_) {
    // Another model (or the same one uploaded again): its ids are not ours.
    selection_.clear();
    attributes_.reset();
    uploaded_revision_.reset();
    listed_revision_.reset();
    dataset_ = source.dataset;
    dataset_address_ = address;
    fiber_count_ = fibers;
  }
  source_fbl_ = source.fbl;
  if (!source.fbl && source.path != opened_path_) {
    opened_path_ = source.path;
    opened_fbl_.reset();
    fbl_error_.clear();
    if (source.path.empty() || !isFblPath(source.path)) {
      fbl_error_ = "the model's .fbl is not available yet";
    } else {
      try {
        opened_fbl_ = FblFile::open(source.path);
      } catch (const Error& e) {
        fbl_error_ = e.what();
      }
    }
  }

  if (dataset_ && fiber_count_ > 0 && uploaded_revision_ != selection_.revision()) {
    if (selection_.empty()) {
      if (attributes_) attributes_->clearSelection();  // address 0: nothing dimmed, no upload needed
    } else {
      if (!attributes_) attributes_.emplace(*context_, fiber_count_);
      const std::vector<uint32_t> words = selection_.bitWords(fiber_count_);
      attributes_->uploadSelection(words);
    }
    uploaded_revision_ = selection_.revision();
  }

  if (listed_revision_ != selection_.revision() || info.exportable != (fbl() != nullptr)) {
    info.fibers.clear();
    for (const uint32_t fiber : selection_.fibers()) info.fibers.push_back({fiber, lengthMm(fiber)});
    info.exportable = fbl() != nullptr;
    listed_revision_ = selection_.revision();
  }
}

void ViewerSelection::pick(const PickResult& result, bool add) {
  const bool hit = result.hit && dataset_ && result.fiber < fiber_count_;
  if (add) {
    if (hit) selection_.toggle(result.fiber);
  } else if (hit) {
    selection_.select(result.fiber);
  } else {
    selection_.clear();
  }
}

const FblFile* ViewerSelection::fbl() const {
  if (source_fbl_) return source_fbl_;
  return opened_fbl_ ? &*opened_fbl_ : nullptr;
}

// The .fbl's "fiber_length_mm" when in reach, else the dataset's length
// buffer on the GPU (the same values: both are the lengths the codec
// measured), one float copied back per fiber.
std::optional<float> ViewerSelection::lengthMm(uint32_t fiber) const {
  try {
    if (const FblFile* file = fbl()) {
      if (std::optional<float> length = fiberLengthMm(*file, fiber)) return length;
    }
    if (dataset_ && fiber < fiber_count_) {
      const gpu::Buffer& lengths = dataset_->fiberLength();
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

void ViewerSelection::exportTck(const std::string& tck_path) const {
  if (selection_.empty()) throw Error("export-selection: no fiber is selected");
  const FblFile* file = fbl();
  if (!file) throw Error("export-selection: " + (fbl_error_.empty() ? "no model" : fbl_error_));
  exportFibers(*file, selection_.fibers(), tck_path);
}

}  // namespace fibscope
