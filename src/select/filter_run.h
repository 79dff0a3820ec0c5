// `fibscope filter`'s work: the streamlines of a reader that a FiberFilter
// keeps, with their per-streamline and per-point data, to a writer, in
// their order. Streams in chunks (memory bounded by two chunks whatever
// the input's size); the next chunk is read while the current one is
// tested (on every core) and written.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "io/reader.h"
#include "io/writer.h"
#include "select/fiber_filter.h"

namespace fibscope {

struct FilterReport {
  uint64_t streamlines = 0, points = 0;  // read
  uint64_t kept = 0, kept_points = 0;
  uint64_t by_length = 0;                // dropped by the length limits
  std::vector<uint64_t> by_scalar;       // per scalar range: dropped for a value outside it (the first missed)
  std::vector<uint64_t> by_exclude;      // per exclude region: dropped by entering it
  std::vector<uint64_t> by_include;      // per include region: dropped for missing it (the first missed)
  uint64_t by_order = 0;                 // dropped for the ordered includes (missed or out of order)
  uint64_t by_distance = 0;              // dropped for lying farther than the threshold from the zone
  // The input header's groups (TRX): written renumbered, and those left
  // without a kept member dropped.
  size_t groups_kept = 0, groups_dropped = 0;

  // Counts one streamline of `points` points with its verdict.
  void count(const FilterVerdict& v, uint64_t points);
  // Adds the counts of a report on other streamlines of the same criteria.
  void add(const FilterReport& other);
};

// Filters everything `reader` gives into `writer` (which the caller
// finishes). The groups of the reader's header become the kept members of
// each at their output indices, in the group's order (writer.renumberGroups;
// an empty group is dropped, as trx-python's select drops it). `progress` is called after each chunk with the reader's
// bytes so far. `threads`: 0 = every core. The filter's scalar ranges
// read the chunks' per-streamline arrays (resolveScalarColumns: an array
// the reader does not give is an Error naming its path, before anything is
// written). Throws what the reader and the writer throw.
FilterReport runFilter(TractogramReader& reader, TractogramWriter& writer, const FiberFilter& filter,
                       unsigned threads = 0, const std::function<void(uint64_t bytes)>& progress = {});

// runFilter for a .tck on disk read in place (io/tck_scan.h): its ranges
// tested on every core straight from the read buffers, and only the kept
// streamlines copied, in their order, to `writer`. `warnings` gets what
// the reader would say at the end of the data (the header's count). Returns
// nullopt when the file cannot be scanned in place (not native float32, or
// not well-formed: see tckScannableInPlace), having written nothing, or when
// damage turns up on the way: then `writer` holds part of the output and is
// to be thrown away, and the reader says what is wrong (runFilter).
// `range_bytes`: the size of the ranges scanned (0: a few per thread, at
// most 16 MiB; tests cut tiny ones to cross every kind of boundary).
std::optional<FilterReport> runTckFilterInPlace(const std::string& path, TractogramWriter& writer,
                                                const FiberFilter& filter, std::vector<std::string>& warnings,
                                                unsigned threads = 0,
                                                const std::function<void(uint64_t bytes)>& progress = {},
                                                uint64_t range_bytes = 0);

// The streamlines of `in` whose `keep` entry is non-zero, with their data,
// appended to `out` (whose arrays must be named as `in`'s).
void appendKeptStreamlines(const Tractogram& in, const std::vector<uint8_t>& keep, Tractogram& out);

// `groups` (indices into a stream of streamlines) for the output that
// keeps those whose bit is set in `kept` (bit i of word i / 64: input
// streamline i; an index beyond the bits counts as dropped): each group's
// kept members renumbered to their rank among the kept, in the group's
// order; a group with none left is dropped.
std::vector<Group> renumberedGroups(const std::vector<Group>& groups, const std::vector<uint64_t>& kept);

}  // namespace fibscope
