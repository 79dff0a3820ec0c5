// runTckFilterInPlace: `fibscope filter` on a .tck without copying what it
// drops. The data is cut into ranges of whole triplets; each is scanned on
// a core of its own straight from its read buffer (io/tck_scan.h), keeps
// copies of the streamlines that pass, and the ranges' kept streamlines are
// written in file order while the next ranges are scanned.
#include <algorithm>
#include <future>
#include <thread>

#include "core/thread_pool.h"
#include "io/tck_scan.h"
#include "select/filter_run.h"

namespace fibscope {
namespace {

// One range's result: what it kept and its counts.
struct RangeResult {
  Tractogram kept;
  FilterReport report;
  bool damaged = false;
};

}  // namespace

std::optional<FilterReport> runTckFilterInPlace(const std::string& path, TractogramWriter& writer,
                                                const FiberFilter& filter, std::vector<std::string>& warnings,
                                                unsigned threads, const std::function<void(uint64_t)>& progress,
                                                uint64_t range_bytes) {
  // A .tck carries no per-streamline values for scalar ranges to test.
  if (!filter.criteria().scalar_ranges.empty()) return std::nullopt;
  TckHeaderInfo info;
  uint64_t file_bytes = 0;
  {
    const MappedFile file(path);
    info = parseTckHeader(file, kTckMagic);
    if (!tckScannableInPlace(file, info)) return std::nullopt;
    file_bytes = file.size();
  }
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  const FilterCriteria& c = filter.criteria();
  const uint64_t begin = info.data_offset, end = file_bytes;
  // Ranges: a few per thread so the slowest range does not hold the others
  // up; at most 16 MiB so the kept copies of two rounds stay bounded
  // whatever the file's size; whole triplets.
  constexpr uint64_t kTriplet = 12;
  if (range_bytes == 0)
    range_bytes = std::clamp<uint64_t>((end - begin) / (uint64_t(threads) * 4), uint64_t(1) << 20, uint64_t(16) << 20);
  range_bytes = std::max(kTriplet, range_bytes / kTriplet * kTriplet);
  const uint64_t ranges = (end - begin + range_bytes - 1) / range_bytes;

  FilterReport total;
  total.by_exclude.assign(c.exclude.size(), 0);
  total.by_include.assign(c.include.size(), 0);
  // Two rounds of results: one being written while the next is scanned.
  std::vector<RangeResult> rounds[2];
  std::future<void> writing;
  auto write = [&writer](const std::vector<RangeResult>& round) {
    for (const RangeResult& r : round) writer.write(r.kept);
  };
  // A read buffer per thread, kept from range to range.
  std::vector<std::unique_ptr<TrackDataStream>> streams(threads);
  for (auto& s : streams) s = std::make_unique<TrackDataStream>(path, begin, end);
  bool damaged = false;
  int current = 0;
  for (uint64_t first = 0; first < ranges && !damaged; first += threads, current ^= 1) {
    const unsigned n = unsigned(std::min<uint64_t>(threads, ranges - first));
    std::vector<RangeResult>& round = rounds[current];
    round.resize(n);
    runPieces(n, [&](unsigned k) {
      RangeResult& r = round[k];
      r.kept.clear();
      r.report = FilterReport{};
      r.report.by_exclude.assign(c.exclude.size(), 0);
      r.report.by_include.assign(c.include.size(), 0);
      r.report.by_scalar.assign(c.scalar_ranges.size(), 0);
      const uint64_t from = begin + (first + k) * range_bytes, to = std::min(end, from + range_bytes);
      TckStreamlineScan scan(*streams[k], begin, from, to);
      TckStreamlineScan::Step step;
      while ((step = scan.next()) == TckStreamlineScan::Step::Streamline) {
        const FilterVerdict v = filter.evaluate(scan.points(), scan.pointCount());
        r.report.count(v, scan.pointCount());
        if (v.kept()) r.kept.addStreamline(scan.points(), scan.pointCount());
      }
      r.damaged = step == TckStreamlineScan::Step::Damaged;
    });
    for (const RangeResult& r : round) {
      damaged = damaged || r.damaged;
      total.add(r.report);
    }
    if (writing.valid()) writing.get();  // the round before, from the other buffer
    if (damaged) break;
    writing = std::async(std::launch::async, write, std::cref(round));
    if (progress) progress(std::min(end, begin + (first + n) * range_bytes));
  }
  if (writing.valid()) writing.get();
  if (damaged) return std::nullopt;
  if (const auto w = tckCountWarning(std::any_of(info.properties.begin(), info.properties.end(),
                                                 [](const auto& kv) { return kv.first == "count"; }),
                                     info.count, total.streamlines))
    warnings.push_back(path + ": " + *w);
  return total;
}

}  // namespace fibscope
