#include "select/filter_run.h"

#include <algorithm>
#include <bit>
#include <future>
#include <thread>

#include "core/thread_pool.h"

namespace fibscope {
namespace {

// Points a chunk holds: large enough that a chunk's work dwarfs the
// threads' start, small enough that two stay in cache-friendly memory.
constexpr size_t kChunkPoints = size_t(1) << 20;

}  // namespace

void FilterReport::count(const FilterVerdict& v, uint64_t n) {
  ++streamlines;
  points += n;
  switch (v.reason) {
    case FilterReason::Kept:
      ++kept;
      kept_points += n;
      break;
    case FilterReason::Length: ++by_length; break;
    case FilterReason::Scalar: ++by_scalar[v.region]; break;
    case FilterReason::Exclude: ++by_exclude[v.region]; break;
    case FilterReason::Include: ++by_include[v.region]; break;
    case FilterReason::IncludeOrdered: ++by_order; break;
    case FilterReason::Distance: ++by_distance; break;
  }
}

void FilterReport::add(const FilterReport& o) {
  streamlines += o.streamlines;
  points += o.points;
  kept += o.kept;
  kept_points += o.kept_points;
  by_length += o.by_length;
  by_order += o.by_order;
  by_distance += o.by_distance;
  by_exclude.resize(std::max(by_exclude.size(), o.by_exclude.size()), 0);
  by_include.resize(std::max(by_include.size(), o.by_include.size()), 0);
  by_scalar.resize(std::max(by_scalar.size(), o.by_scalar.size()), 0);
  for (size_t i = 0; i < o.by_scalar.size(); ++i) by_scalar[i] += o.by_scalar[i];
  for (size_t i = 0; i < o.by_exclude.size(); ++i) by_exclude[i] += o.by_exclude[i];
  for (size_t i = 0; i < o.by_include.size(); ++i) by_include[i] += o.by_include[i];
}

void appendKeptStreamlines(const Tractogram& in, const std::vector<uint8_t>& keep, Tractogram& out) {
  for (size_t s = 0; s < in.streamlineCount(); ++s) {
    if (!keep[s]) continue;
    const uint64_t first = in.offsets[s], n = in.pointsIn(s);
    out.addStreamline(in.point(first), n);
    for (size_t a = 0; a < in.per_streamline.size(); ++a) {
      const DataArray& from = in.per_streamline[a];
      const auto begin = from.values.begin() + ptrdiff_t(s * from.components);
      out.per_streamline[a].values.insert(out.per_streamline[a].values.end(), begin, begin + from.components);
    }
    for (size_t a = 0; a < in.per_point.size(); ++a) {
      const DataArray& from = in.per_point[a];
      const auto begin = from.values.begin() + ptrdiff_t(first * from.components);
      out.per_point[a].values.insert(out.per_point[a].values.end(), begin, begin + ptrdiff_t(n * from.components));
    }
  }
}

std::vector<Group> renumberedGroups(const std::vector<Group>& groups, const std::vector<uint64_t>& kept) {
  // rank[w]: the kept streamlines before word w.
  std::vector<uint64_t> rank(kept.size() + 1, 0);
  for (size_t w = 0; w < kept.size(); ++w) rank[w + 1] = rank[w] + uint64_t(std::popcount(kept[w]));
  std::vector<Group> out;
  for (const Group& g : groups) {
    Group renumbered{g.name, {}};
    for (const uint32_t s : g.streamlines) {
      const size_t w = s / 64;
      const uint64_t bit = uint64_t(1) << (s % 64);
      if (w >= kept.size() || !(kept[w] & bit)) continue;
      renumbered.streamlines.push_back(uint32_t(rank[w] + uint64_t(std::popcount(kept[w] & (bit - 1)))));
    }
    if (!renumbered.streamlines.empty()) out.push_back(std::move(renumbered));
  }
  return out;
}

FilterReport runFilter(TractogramReader& reader, TractogramWriter& writer, const FiberFilter& filter,
                       unsigned threads, const std::function<void(uint64_t)>& progress) {
  const FilterCriteria& c = filter.criteria();
  FilterReport report;
  report.by_exclude.assign(c.exclude.size(), 0);
  report.by_include.assign(c.include.size(), 0);
  report.by_scalar.assign(c.scalar_ranges.size(), 0);
  const std::string& path = reader.header().path;
  resolveScalarColumns(c.scalar_ranges, reader.header().per_streamline, path);
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());

  Tractogram chunks[2], kept;
  std::vector<FilterVerdict> verdicts;
  std::vector<uint8_t> keep;
  // Which input streamlines are kept, for the header's groups (a bit each).
  const bool grouped = !reader.header().groups.empty();
  std::vector<uint64_t> kept_bits;
  bool more = reader.read(chunks[0], kChunkPoints);
  for (int current = 0; more; current ^= 1) {
    const Tractogram& chunk = chunks[current];
    // The next chunk is read on another thread while this one is tested
    // and written (the reader is used by one thread at a time).
    std::future<bool> next = std::async(std::launch::async, [&reader, &chunks, current] {
      return reader.read(chunks[current ^ 1], kChunkPoints);
    });
    const size_t n = chunk.streamlineCount();
    verdicts.assign(n, FilterVerdict{});
    const unsigned pieces = unsigned(std::min<size_t>(threads, std::max<size_t>(1, chunk.pointCount() / 65536)));
    // The chunk's own arrays (their order is the reader's to choose).
    const std::vector<ScalarColumn> columns = resolveScalarColumns(c.scalar_ranges, chunk.per_streamline, path);
    runPieces(pieces, [&](unsigned piece) {
      float scalars[FiberFilter::kMaxScalarRanges];
      for (size_t s = n * piece / pieces; s < n * (piece + 1) / pieces; ++s) {
        for (size_t r = 0; r < columns.size(); ++r) {
          const DataArray& a = chunk.per_streamline[columns[r].array];
          scalars[r] = a.values[s * a.components + columns[r].component];
        }
        verdicts[s] = filter.evaluate(chunk.point(chunk.offsets[s]), chunk.pointsIn(s),
                                      std::span<const float>(scalars, columns.size()));
      }
    });
    const uint64_t before = report.streamlines;  // input index of the chunk's first
    keep.assign(n, 0);
    for (size_t s = 0; s < n; ++s) {
      keep[s] = verdicts[s].kept();
      report.count(verdicts[s], chunk.pointsIn(s));
    }
    if (grouped) {
      kept_bits.resize((before + n + 63) / 64, 0);
      for (size_t s = 0; s < n; ++s)
        if (keep[s]) kept_bits[(before + s) / 64] |= uint64_t(1) << ((before + s) % 64);
    }
    kept.clear();
    if (kept.per_streamline.size() != chunk.per_streamline.size() || kept.per_point.size() != chunk.per_point.size()) {
      kept.per_streamline.clear();
      kept.per_point.clear();
      for (const DataArray& a : chunk.per_streamline) kept.per_streamline.push_back({a.name, a.components, a.dtype, {}});
      for (const DataArray& a : chunk.per_point) kept.per_point.push_back({a.name, a.components, a.dtype, {}});
    }
    appendKeptStreamlines(chunk, keep, kept);
    writer.write(kept);
    more = next.get();
    if (progress) progress(reader.bytesRead());
  }
  if (grouped) {
    const std::vector<Group>& groups = reader.header().groups;
    std::vector<Group> renumbered = renumberedGroups(groups, kept_bits);
    report.groups_kept = renumbered.size();
    report.groups_dropped = groups.size() - renumbered.size();
    writer.renumberGroups(std::move(renumbered));
  }
  return report;
}

}  // namespace fibscope
