// The in-memory tractogram: one plain struct of arrays.
//
// A whole file and a streamed chunk of a file have the same type, so readers
// fill the same struct either way. Points are in world space: RAS+
// millimetres (DESIGN.md section 4); readers convert on the way in.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace fibscope {

// A named per-streamline or per-point array, stored as float whatever the
// file held; `dtype` remembers the file's type ("float32", "uint8", ...) so a
// writer of the same format can store it back the same way.
struct DataArray {
  std::string name;
  uint32_t components = 1;
  std::string dtype = "float32";
  std::vector<float> values;  // size = (streamlines or points) * components
};

// A TRX group: a named subset of streamlines, by index into the whole file.
struct Group {
  std::string name;
  std::vector<uint32_t> streamlines;
};

struct Tractogram {
  std::vector<float> positions;           // x,y,z interleaved; 3 * pointCount()
  std::vector<uint64_t> offsets = {0};    // streamline i is points [offsets[i], offsets[i+1])
  std::vector<DataArray> per_streamline;  // values per streamline
  std::vector<DataArray> per_point;       // values per point

  size_t streamlineCount() const { return offsets.size() - 1; }
  size_t pointCount() const { return offsets.back(); }
  size_t pointsIn(size_t streamline) const { return offsets[streamline + 1] - offsets[streamline]; }
  const float* point(size_t index) const { return positions.data() + 3 * index; }

  // Empties the arrays but keeps their capacity and the data array names, so
  // a reader can refill one chunk without reallocating.
  void clear();
  // Appends one streamline of n points (x,y,z interleaved).
  void addStreamline(const float* xyz, size_t n);
  // Appends all of `other` (same data array names in the same order).
  void append(const Tractogram& other);
  // Checks the invariants (offsets monotone, array sizes); returns "" when
  // consistent, else what is wrong. Used by tests and after readers.
  std::string validate() const;
};

// Where the points came from: the voxel grid of the reference image, if the
// format carries one (trk, trx; tck has none).
struct Space {
  bool known = false;
  std::array<float, 16> voxel_to_rasmm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // row-major 4x4
  std::array<int32_t, 3> dimensions = {0, 0, 0};
  std::array<float, 3> voxel_sizes = {1, 1, 1};
  std::string voxel_order = "RAS";
};

// What a reader knows before reading any streamline.
struct TractogramHeader {
  std::string path;
  std::string format;                     // "tck", "trk", "trx", "vtk", ...
  uint64_t file_bytes = 0;
  int64_t declared_streamlines = -1;      // from the header; -1 when the format has none
  int64_t declared_points = -1;
  Space space;
  // Format-specific key/value pairs kept for round trips (tck header keys in
  // file order, trk fields, trx header.json extras).
  std::vector<std::pair<std::string, std::string>> properties;
  // Names, component counts and dtypes of the data arrays, values empty.
  std::vector<DataArray> per_streamline;
  std::vector<DataArray> per_point;
  std::vector<Group> groups;              // TRX groups (whole file)

  // Returns the value of property `key`, or "" if absent.
  std::string property(const std::string& key) const;
};

// Arc length in mm of the polyline of `n` points at `p` (x y z each), over
// its finite segments. Each segment's length in single precision (sqrtss: a
// per-segment sqrtsd was a visible part of the compressor's time), summed in
// double.
float polylineLength(const float* p, size_t n);

}  // namespace fibscope
