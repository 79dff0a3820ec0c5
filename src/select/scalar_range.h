// Per-fiber scalars carried from the file (trk properties, TRX dps, .fbl
// dps sections, VTK cell data) as a criterion of the fiber filter: a range
// of one component of a per-streamline array, e.g. fa_mean in [0.3, inf].
//
// Spec (the command line's --fiber-scalar, the viewer script's words;
// --scalar-range is the colormap's range):
//   NAME:MIN:MAX  or  NAME[K]:MIN:MAX   (K: the component, default 0)
// MIN or MAX empty = an open end ("fa_mean:0.3:" keeps fa_mean >= 0.3).
// The last two colons split the spec, so a name may hold colons.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/tractogram.h"
#include "io/reader.h"

namespace fibscope {

struct ScalarRange {
  std::string name;        // the per-streamline array
  uint32_t component = 0;  // which of its components
  double min = NAN;        // NaN: open (no lower limit)
  double max = NAN;        // NaN: open (no upper limit)
  bool operator==(const ScalarRange&) const = default;  // (NaN != NaN: compare specs for identity)
};

// Throws Error (one line, naming the spec and what is wrong) for a spec
// not of the form above, a bound that is not a finite number, a component
// that is not a small integer, or MIN above MAX. Safe on untrusted text.
ScalarRange parseScalarRange(std::string_view spec);
// The spec again (parseScalarRange(scalarRangeSpec(r)) == r to the double).
std::string scalarRangeSpec(const ScalarRange& range);
// "NAME" for component 0, else "NAME[K]"; "NAME[0]" where NAME ends in "]".
std::string scalarRangeArray(const ScalarRange& range);
// For reports: "fa_mean outside [0.3, inf]" (open ends as -inf / inf).
std::string scalarRangeOutside(const ScalarRange& range);
// Throws Error naming `what` for MIN above MAX or a non-finite bound.
void checkScalarRange(const ScalarRange& range, const std::string& what);

// Where a range's values lie in a list of per-streamline arrays.
struct ScalarColumn {
  size_t array = 0;        // index into the list
  uint32_t component = 0;
};

// The columns of `ranges` in `arrays` (a header's or a chunk's
// per_streamline). Throws Error, one line naming `path`, the missing array
// (or the component beyond its count) and listing the arrays it has ("none"
// for a file without any, e.g. a .tck).
std::vector<ScalarColumn> resolveScalarColumns(std::span<const ScalarRange> ranges,
                                               std::span<const DataArray> arrays, const std::string& path);

// Each range's value for every streamline of `t` (values[r][s]), its
// arrays found as resolveScalarColumns finds them (`path` names it).
std::vector<std::vector<float>> scalarValues(const Tractogram& t, std::span<const ScalarRange> ranges,
                                             const std::string& path);
// The same for every streamline `reader` gives (read to its end, chunk by
// chunk: only the values stay in memory). Throws what the reader throws.
std::vector<std::vector<float>> readScalarValues(TractogramReader& reader, std::span<const ScalarRange> ranges);

// "a, rgb[3], weight" (each array with its component count when > 1), or "none".
std::string arrayNamesList(std::span<const DataArray> arrays);

}  // namespace fibscope
