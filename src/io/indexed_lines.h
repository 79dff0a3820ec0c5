// Streamlines as lists of point ids into one shared point array (VTK's
// legacy and XML PolyData): copies one line's points, point data and line
// data into a chunk. Both VTK readers hold the points and arrays in memory
// and hand out chunks through this.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/tractogram.h"

namespace fibscope {

struct IndexedPoints {
  const std::string& path;                   // for messages
  const std::vector<float>& points;          // x, y, z per point id
  const std::vector<DataArray>& point_arrays;  // values per point id
  const std::vector<DataArray>& line_arrays;   // values per line
  bool lps = false;                          // stored in LPS: negate x and y
};

// Appends line `line`: `k` points whose ids `id(j)` gives (the caller checks
// them against the point count). A non-finite point is an Error.
template <typename Id>
void appendIndexedLine(Tractogram& chunk, const IndexedPoints& src, uint64_t line, uint64_t k, Id id) {
  const size_t first = chunk.pointCount();
  chunk.positions.resize(3 * (first + k));
  float* out = chunk.positions.data() + 3 * first;
  for (uint64_t j = 0; j < k; ++j) {
    const uint64_t p_id = id(j);
    const float* p = src.points.data() + 3 * p_id;
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      fail(src.path, "line " + std::to_string(line) + " uses point " + std::to_string(p_id) +
                         ", which has a non-finite coordinate");
    out[3 * j + 0] = src.lps ? -p[0] : p[0];
    out[3 * j + 1] = src.lps ? -p[1] : p[1];
    out[3 * j + 2] = p[2];
    for (size_t a = 0; a < src.point_arrays.size(); ++a) {
      const uint32_t n = src.point_arrays[a].components;
      const float* v = src.point_arrays[a].values.data() + p_id * n;
      chunk.per_point[a].values.insert(chunk.per_point[a].values.end(), v, v + n);
    }
  }
  for (size_t a = 0; a < src.line_arrays.size(); ++a) {
    const uint32_t n = src.line_arrays[a].components;
    const float* v = src.line_arrays[a].values.data() + line * n;
    chunk.per_streamline[a].values.insert(chunk.per_streamline[a].values.end(), v, v + n);
  }
  chunk.offsets.push_back(first + k);
}

}  // namespace fibscope
