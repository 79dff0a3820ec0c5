// Streaming TrackVis .trk writer.
//
// Writes version 2, little-endian (as nibabel does) under a temporary name;
// points go from RAS+ mm to voxmm through the inverse of the reader's affine
// so that fibscope and nibabel read back what was written. n_count (and, for
// a synthetic grid, the dimensions) are patched into the header at finish().
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/byte_order.h"
#include "core/error.h"
#include "core/output_file.h"
#include "io/tck_format.h"  // printableExcerpt
#include "io/trk_format.h"
#include "io/writer.h"

namespace fibscope {
namespace {

constexpr bool kSwapOut = !kHostIsLittleEndian;

// Parses `count` space-separated floats of property `key`; false if absent or malformed.
bool floatsProperty(const TractogramHeader& like, const std::string& key, float* out, size_t count) {
  const std::string text = like.property(key);
  if (text.empty()) return false;
  const char* p = text.c_str();
  for (size_t i = 0; i < count; ++i) {
    char* end = nullptr;
    out[i] = std::strtof(p, &end);
    if (end == p) return false;
    p = end;
  }
  return true;
}

// True when `grid` gives a usable affine: finite, invertible, valid order and sizes.
bool usableGrid(const TrkGrid& grid) {
  for (float v : grid.vox_to_ras)
    if (!std::isfinite(v)) return false;
  if (grid.vox_to_ras[15] == 0 || affineAxisCodes(grid.vox_to_ras).empty()) return false;
  for (float s : grid.voxel_sizes)
    if (!std::isfinite(s) || s == 0) return false;
  return validTrkVoxelOrder(grid.voxel_order);
}

class TrkWriter final : public TractogramWriter {
 public:
  TrkWriter(const std::string& path, const TractogramHeader& like, const WriterOptions& options);
  void write(const Tractogram& chunk) override;
  void finish() override;

 private:
  struct Column {
    std::string name;        // as in the input tractogram
    uint32_t components = 1;
  };
  TrkGrid chooseGrid(const TractogramHeader& like);
  void chooseColumns(const std::vector<DataArray>& arrays, std::vector<Column>& columns,
                     std::array<std::array<char, kTrkNameBytes>, kTrkMaxNames>& names, int16_t& count,
                     const char* what);
  static const DataArray& findArray(const std::vector<DataArray>& arrays, const Column& column, size_t index,
                                    size_t expected_values, const std::string& path, const char* what);

  OutputFile out_;
  TrkHeader trk_;
  Affine4 from_ras_{};
  bool synthetic_grid_ = false;
  std::vector<Column> scalars_;
  std::vector<Column> properties_;
  uint64_t streamlines_ = 0;
  std::array<double, 3> max_voxmm_ = {0, 0, 0};
  std::vector<uint8_t> buffer_;
  bool finished_ = false;
};

TrkWriter::TrkWriter(const std::string& path, const TractogramHeader& like, const WriterOptions& options)
    : out_(path, options.overwrite) {
  const TrkGrid grid = chooseGrid(like);
  trk_.dimensions = grid.dimensions;
  trk_.voxel_sizes = grid.voxel_sizes;
  trk_.vox_to_ras = grid.vox_to_ras;
  trk_.voxel_order = {grid.voxel_order[0], grid.voxel_order[1], grid.voxel_order[2], '\0'};
  // Fields that only matter to TrackVis itself, carried over from a trk input.
  floatsProperty(like, "trk.origin", trk_.origin.data(), 3);
  floatsProperty(like, "trk.image_orientation_patient", trk_.image_orientation_patient.data(), 6);
  static const char* kFlagNames[6] = {"invert_x", "invert_y", "invert_z", "swap_xy", "swap_yz", "swap_zx"};
  for (int i = 0; i < 6; ++i) {
    const std::string v = like.property(std::string("trk.") + kFlagNames[i]);
    if (!v.empty()) trk_.invert_swap[i] = static_cast<uint8_t>(std::strtoul(v.c_str(), nullptr, 10));
  }
  trk_.version = 2;
  trk_.n_count = 0;  // patched in finish(); 0 means "unknown" until then

  chooseColumns(like.per_point, scalars_, trk_.scalar_names, trk_.n_scalars, "per-point");
  chooseColumns(like.per_streamline, properties_, trk_.property_names, trk_.n_properties, "per-streamline");
  if (!like.groups.empty())
    warn("trk has no groups: " + std::to_string(like.groups.size()) + " group(s) starting with '" +
         like.groups.front().name + "' are not written");

  from_ras_ = invertAffine(trkVoxmmToRasmm(grid));
  uint8_t bytes[kTrkHeaderBytes];
  serializeTrkHeader(trk_, bytes);
  out_.write(bytes, kTrkHeaderBytes);
}

TrkGrid TrkWriter::chooseGrid(const TractogramHeader& like) {
  TrkGrid grid;
  if (like.space.known) {
    grid.vox_to_ras = like.space.voxel_to_rasmm;
    bool dims_fit = true;
    for (int k = 0; k < 3; ++k) {
      const int32_t d = like.space.dimensions[k];
      dims_fit = dims_fit && d >= 0 && d <= std::numeric_limits<int16_t>::max();
      grid.dimensions[k] = static_cast<int16_t>(std::clamp<int32_t>(d, 0, std::numeric_limits<int16_t>::max()));
    }
    if (!dims_fit) warn("grid dimensions do not fit trk's int16 fields; clamped to 0..32767");
    if (like.format == "trk") {
      grid.voxel_sizes = like.space.voxel_sizes;
      grid.voxel_order = like.space.voxel_order;
    } else {
      // Other formats carry only the affine: take voxel sizes and axis order
      // from it (as DIPY does), which makes the re-orientation the identity.
      for (int j = 0; j < 3; ++j) {
        const float* a = grid.vox_to_ras.data();
        grid.voxel_sizes[j] = std::sqrt(a[j] * a[j] + a[4 + j] * a[4 + j] + a[8 + j] * a[8 + j]);
      }
      grid.voxel_order = affineAxisCodes(grid.vox_to_ras);
    }
    if (usableGrid(grid)) return grid;
    warn("the input's voxel grid cannot define trk voxmm (singular or non-finite affine); ignoring it");
  }
  if (trkGridFromProperties(like.properties, grid)) return grid;
  // No grid: identity with 1 mm voxels, so voxmm = RAS + 0.5. The dimensions
  // are set to cover the data at finish().
  synthetic_grid_ = true;
  warn("no voxel grid is known for this tractogram; writing a synthetic identity grid with 1 mm voxels");
  return TrkGrid{};
}

void TrkWriter::chooseColumns(const std::vector<DataArray>& arrays, std::vector<Column>& columns,
                              std::array<std::array<char, kTrkNameBytes>, kTrkMaxNames>& names, int16_t& count,
                              const char* what) {
  int total = 0;
  for (const DataArray& array : arrays) {
    if (columns.size() == size_t(kTrkMaxNames)) {
      warn(std::string(what) + " array '" + array.name + "' is not written: trk names at most 10 arrays");
      continue;
    }
    if (array.components == 0 || total + int64_t(array.components) > std::numeric_limits<int16_t>::max()) {
      warn(std::string(what) + " array '" + array.name + "' is not written: " + std::to_string(array.components) +
           " components do not fit trk's count");
      continue;
    }
    std::string name = array.name.empty() ? std::string(what) + "_" + std::to_string(columns.size()) : array.name;
    if (!encodeTrkName(name, array.components, names[columns.size()]))
      warn(std::string(what) + " array '" + array.name + "' is stored under a name shortened to 20 bytes");
    columns.push_back({array.name, array.components});
    total += int(array.components);
  }
  count = static_cast<int16_t>(total);
}

const DataArray& TrkWriter::findArray(const std::vector<DataArray>& arrays, const Column& column, size_t index,
                                      size_t expected_values, const std::string& path, const char* what) {
  const DataArray* found = nullptr;
  if (index < arrays.size() && arrays[index].name == column.name) found = &arrays[index];
  for (size_t i = 0; !found && i < arrays.size(); ++i)
    if (arrays[i].name == column.name) found = &arrays[i];
  // Names come from input headers: printable, so the message stays one line.
  if (!found)
    fail(path, std::string("chunk lacks the ") + what + " array '" + printableExcerpt(column.name) +
                   "' named in the header");
  if (found->components != column.components || found->values.size() != expected_values)
    fail(path, std::string("chunk's ") + what + " array '" + printableExcerpt(column.name) + "' has " +
                   std::to_string(found->values.size()) + " values of " + std::to_string(found->components) +
                   " components, expected " + std::to_string(expected_values) + " of " +
                   std::to_string(column.components));
  return *found;
}

void TrkWriter::write(const Tractogram& chunk) {
  if (finished_) fail(out_.path(), "internal error: write() after finish()");
  const std::string problem = chunk.validate();
  if (!problem.empty()) fail(out_.path(), "inconsistent chunk: " + problem);
  const size_t n_streamlines = chunk.streamlineCount();
  // An empty chunk carries no values, so it need not hold the header's
  // arrays (a file whose every streamline was dropped is written empty).
  if (n_streamlines == 0) return;
  const size_t n_points = chunk.pointCount();
  // Map the header's columns to the chunk's arrays (same order, checked by name).
  std::vector<const float*> scalar_values, property_values;
  for (size_t i = 0; i < scalars_.size(); ++i)
    scalar_values.push_back(
        findArray(chunk.per_point, scalars_[i], i, n_points * scalars_[i].components, out_.path(), "per-point")
            .values.data());
  for (size_t i = 0; i < properties_.size(); ++i)
    property_values.push_back(findArray(chunk.per_streamline, properties_[i], i,
                                        n_streamlines * properties_[i].components, out_.path(), "per-streamline")
                                  .values.data());

  const uint64_t point_bytes = 4 * (3 + uint64_t(trk_.n_scalars));
  const uint64_t property_bytes = 4 * uint64_t(trk_.n_properties);
  buffer_.resize(n_streamlines * (4 + property_bytes) + n_points * point_bytes);
  uint8_t* p = buffer_.data();
  const double* a = from_ras_.data();
  for (size_t s = 0; s < n_streamlines; ++s) {
    const uint64_t first = chunk.offsets[s];
    const uint64_t m = chunk.pointsIn(s);
    if (m > uint64_t(std::numeric_limits<int32_t>::max()))
      fail(out_.path(), "streamline " + std::to_string(streamlines_ + s) + " has " + std::to_string(m) +
                            " points, more than trk's int32 count can hold");
    storeUnaligned<int32_t>(p, static_cast<int32_t>(m), kSwapOut);
    p += 4;
    for (uint64_t j = first; j < first + m; ++j) {
      const float* r = chunk.point(j);
      if (!std::isfinite(r[0]) || !std::isfinite(r[1]) || !std::isfinite(r[2]))
        fail(out_.path(), "streamline " + std::to_string(streamlines_ + s) + " point " + std::to_string(j - first) +
                              " is not finite; trk readers reject such points");
      const double x = r[0], y = r[1], z = r[2];
      for (int k = 0; k < 3; ++k) {
        const float v = static_cast<float>(a[4 * k] * x + a[4 * k + 1] * y + a[4 * k + 2] * z + a[4 * k + 3]);
        if (!std::isfinite(v))
          fail(out_.path(), "streamline " + std::to_string(streamlines_ + s) + " point " + std::to_string(j - first) +
                                " lies outside the float range of the voxel grid's voxmm coordinates");
        max_voxmm_[k] = std::max(max_voxmm_[k], double(v));
        storeUnaligned<float>(p + 4 * k, v, kSwapOut);
      }
      p += 12;
      for (size_t c = 0; c < scalars_.size(); ++c) {
        const uint32_t n = scalars_[c].components;
        for (uint32_t i = 0; i < n; ++i) storeUnaligned<float>(p + 4 * i, scalar_values[c][j * n + i], kSwapOut);
        p += 4 * n;
      }
    }
    for (size_t c = 0; c < properties_.size(); ++c) {
      const uint32_t n = properties_[c].components;
      for (uint32_t i = 0; i < n; ++i) storeUnaligned<float>(p + 4 * i, property_values[c][s * n + i], kSwapOut);
      p += 4 * n;
    }
  }
  out_.write(buffer_.data(), buffer_.size());
  streamlines_ += n_streamlines;
}

void TrkWriter::finish() {
  if (finished_) fail(out_.path(), "internal error: finish() called twice");
  finished_ = true;
  if (streamlines_ > uint64_t(std::numeric_limits<int32_t>::max())) {
    warn("more streamlines than trk's n_count can hold; n_count is left 0 (unknown)");
  } else {
    uint8_t count[4];
    storeUnaligned<int32_t>(count, static_cast<int32_t>(streamlines_), kSwapOut);
    out_.writeAt(trk_field::kCount, count, 4);
  }
  if (synthetic_grid_) {
    // Identity grid in RAS order: the dimensions do not enter the affine, so
    // they can be chosen now to cover the data (tools draw the grid box).
    uint8_t dims[6];
    for (int k = 0; k < 3; ++k) {
      const double extent = std::ceil(std::min(max_voxmm_[k], 32767.0));
      storeUnaligned<int16_t>(dims + 2 * k, static_cast<int16_t>(std::max(1.0, extent)), kSwapOut);
    }
    out_.writeAt(trk_field::kDimensions, dims, 6);
  }
  out_.commit();
}

}  // namespace

std::unique_ptr<TractogramWriter> createTrkWriter(const std::string& path, const TractogramHeader& like,
                                                  const WriterOptions& options) {
  return std::make_unique<TrkWriter>(path, like, options);
}

}  // namespace fibscope
