// The viewer's fiber selection (click, ctrl-click, clear), its bit mask for
// the GPU highlight, and the export of the selected fibers from a .fbl to a
// .tck (decoded on the CPU exactly as `fibscope decompress` decodes them).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "codec/fbl_file.h"
#include "core/tractogram.h"

namespace fibscope {

// Fiber ids (streamline indices) in the order they were selected, each once.
class FiberSelection {
 public:
  // Plain click: the selection becomes exactly {fiber}.
  void select(uint32_t fiber);
  // Ctrl-click: adds the fiber at the end, or removes it if selected.
  void toggle(uint32_t fiber);
  // Adds the fiber at the end unless already selected.
  void add(uint32_t fiber);
  void remove(uint32_t fiber);
  void clear();
  bool contains(uint32_t fiber) const;
  bool empty() const { return fibers_.empty(); }
  size_t size() const { return fibers_.size(); }
  const std::vector<uint32_t>& fibers() const { return fibers_; }  // in selection order
  // Changes with every modification (the viewer re-uploads the bits when it
  // differs from the one it uploaded).
  uint64_t revision() const { return revision_; }

  // One bit per fiber for the GPU (GpuScene::selection_bits): word
  // fiber / 32, bit fiber % 32 (LSB first), ceil(fiber_count / 32) words;
  // ids >= fiber_count are left out.
  std::vector<uint32_t> bitWords(uint64_t fiber_count) const;

 private:
  std::vector<uint32_t> fibers_;
  uint64_t revision_ = 0;
};

// The fibers `fibers` (in that order, duplicates as often as listed) of the
// .fbl `file`, decoded as exportFibers writes them (world mm, equal to
// `fibscope decompress`'s points), handed to `sink` in chunks of at least
// `chunk_points` points (the last may hold fewer) after every id and fiber
// was checked. Throws Error as exportFibers. Safe on untrusted files.
void decodeFibers(const FblFile& file, std::span<const uint32_t> fibers, size_t chunk_points,
                  const std::function<void(const Tractogram&)>& sink);

// Writes the fibers `fibers` (in that order, duplicates written as often as
// listed) of the .fbl `file` to the .tck `tck_path`: their fiblets decoded
// on the CPU in the Sequential order and converted to world mm exactly as
// openFbl does (so the points equal `fibscope decompress`'s bit for bit),
// through the tck writer (temporary file + rename: the path never holds a
// partial file). Overwrites an existing file when `overwrite`.
// Throws Error (one line naming the .fbl or the .tck) for an empty list, an
// id >= the file's fiber count, a fiber whose table entries or fiblet flags
// are inconsistent, or a write failure. Safe on untrusted files.
void exportFibers(const FblFile& file, std::span<const uint32_t> fibers, const std::string& tck_path,
                  bool overwrite = true);

// The fiber's length in mm from the "fiber_length_mm" section (the length
// of the streamline as it was compressed); nullopt when the file has no
// such section (or it is not float32 per fiber). Throws Error naming the
// file for an id >= the fiber count.
std::optional<float> fiberLengthMm(const FblFile& file, uint64_t fiber);

}  // namespace fibscope
