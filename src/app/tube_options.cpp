#include "app/tube_options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <unordered_set>

#include "app/open_input.h"
#include "core/error.h"
#include "phantom/phantom.h"

namespace fibscope {

void addTubeCliOptions(CLI::App* cmd, TubeCliOptions& o) {
  cmd->add_option(
         "--tubes", o.fibers,
         "Draw these fibers as ray-cast spline tubes over the lines: all, filtered (the filter's kept fibers), or "
         "indices and ranges (0-99,512)")
      ->each([&o](const std::string&) { o.given = true; });
  cmd->add_option("--tube-radius", o.radius_mm, "Tube radius in mm (default 0.5)");
  cmd->add_flag("--tubes-dim-rest", o.dim_rest,
                "Make the tube fibers the selection: their lines highlighted, the others dimmed (--dim)");
  cmd->add_option(
      "--tube-tolerance", o.resample_tolerance_mm,
      "Resample the tubes' centre lines within this distance of the fibers in mm (default: radius / 20; 0 keeps "
      "every point)");
}

std::vector<uint32_t> parseFiberSelection(const std::string& text, uint64_t count) {
  std::vector<uint32_t> out;
  if (text == "all") {
    if (count > UINT32_MAX) throw Error("--tubes: too many fibers for tubes (" + std::to_string(count) + ")");
    out.resize(count);
    for (uint64_t i = 0; i < count; ++i) out[i] = uint32_t(i);
    return out;
  }
  const auto bad = [&](const std::string& why) {
    throw Error("--tubes: expected all or fiber indices and ranges such as 0-99,512, got '" + text + "': " + why);
  };
  if (text.empty()) bad("empty");
  std::unordered_set<uint32_t> seen;
  size_t at = 0;
  while (at <= text.size()) {
    const size_t end = std::min(text.find(',', at), text.size());
    const std::string_view item(text.data() + at, end - at);
    const size_t dash = item.find('-');
    uint64_t lo = 0, hi = 0;
    const auto number = [&](std::string_view s, uint64_t& v) {
      const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
      if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size()) bad("'" + std::string(s) + "' is no index");
    };
    if (dash == std::string_view::npos) {
      number(item, lo);
      hi = lo;
    } else {
      number(item.substr(0, dash), lo);
      number(item.substr(dash + 1), hi);
      if (hi < lo) bad("the range " + std::string(item) + " is reversed");
    }
    if (hi >= count) bad("fiber " + std::to_string(hi) + " is out of range (" + std::to_string(count) + " fibers)");
    for (uint64_t i = lo; i <= hi; ++i)
      if (seen.insert(uint32_t(i)).second) out.push_back(uint32_t(i));
    at = end + 1;
  }
  return out;
}

TubeModel loadTubeModel(const std::string& path, uint64_t phantom_streamlines, const TubeCliOptions& options,
                        TubeBuildStats* stats, const std::vector<uint32_t>* filtered) {
  if (!(options.radius_mm > 0.0f) || !std::isfinite(options.radius_mm))
    throw Error("--tube-radius: expected a radius > 0 mm, got " + std::to_string(options.radius_mm));
  if (!(options.tolerance() >= 0.0f) || !std::isfinite(options.tolerance()))
    throw Error("--tube-tolerance: expected a distance >= 0 mm, got " + std::to_string(options.resample_tolerance_mm));
  PhantomOptions phantom;
  phantom.streamlines = phantom_streamlines;
  const auto open = [&]() { return path.empty() ? openPhantom(phantom) : openInput(path); };
  // The count first: "all" and the range check need it (a header may not
  // state it, so count by reading when it does not).
  uint64_t count = 0;
  {
    auto reader = open();
    if (reader->header().declared_streamlines >= 0) {
      count = uint64_t(reader->header().declared_streamlines);
    } else {
      Tractogram chunk;
      while (reader->read(chunk)) count += chunk.streamlineCount();
    }
  }
  std::vector<uint32_t> wanted;
  if (options.fibers == "filtered") {
    if (!filtered) throw Error("--tubes filtered: give the fiber filter's criteria (--include, --exclude, ...)");
    wanted = *filtered;
    for (uint32_t f : wanted)
      if (f >= count) throw Error("--tubes filtered: fiber " + std::to_string(f) + " is out of range");
  } else {
    wanted = parseFiberSelection(options.fibers, count);
  }
  if (wanted.empty())
    throw Error(options.fibers == "filtered" ? "--tubes filtered: the filter kept no fibers"
                                             : "--tubes: no fibers selected");
  std::vector<uint32_t> sorted = wanted;
  std::sort(sorted.begin(), sorted.end());
  // The selected streamlines, in index order.
  Tractogram selected;
  {
    auto reader = open();
    Tractogram chunk;
    uint64_t first = 0;
    size_t next = 0;
    while (next < sorted.size() && reader->read(chunk)) {
      for (size_t i = 0; i < chunk.streamlineCount() && next < sorted.size(); ++i)
        if (first + i == sorted[next]) {
          selected.addStreamline(chunk.point(chunk.offsets[i]), chunk.pointsIn(i));
          ++next;
        }
      first += chunk.streamlineCount();
    }
    if (next < sorted.size())
      throw Error((path.empty() ? std::string("phantom") : path) + ": fiber " + std::to_string(sorted[next]) +
                  " was not found (the input ended after " + std::to_string(first) + " streamlines)");
  }
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < selected.pointCount(); ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], selected.point(i)[k]);
      hi[k] = std::max(hi[k], selected.point(i)[k]);
    }
  const float extent = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                 (hi[2] - lo[2]) * (hi[2] - lo[2]));
  if (selected.pointCount() > 1 && options.radius_mm > extent)
    throw Error("--tube-radius: " + std::to_string(options.radius_mm) +
                " mm is larger than the selected fibers' extent (" + std::to_string(extent) + " mm across)");
  TubeBuildOptions build;
  build.radius.radius = options.radius_mm;
  build.resample_tolerance = options.tolerance();
  // In the order given: the position of each wanted fiber among the sorted.
  build.fibers.reserve(wanted.size());
  for (uint32_t f : wanted)
    build.fibers.push_back(uint32_t(std::lower_bound(sorted.begin(), sorted.end(), f) - sorted.begin()));
  TubeModel model = buildTubes(selected, build, stats);
  // Fiber ids are the input's indices.
  for (TubeModel::Tube& t : model.tubes) t.fiber = sorted[t.fiber];
  for (shader::TubeSegment& s : model.segments) s.fiber = sorted[s.fiber];
  return model;
}

}  // namespace fibscope
