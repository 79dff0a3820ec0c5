#include "app/tube_options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <unordered_set>

#include "app/open_input.h"
#include "core/error.h"
#include "io/reader.h"
#include "phantom/phantom.h"
#include "select/number_list.h"

namespace fibscope {
namespace {

// --tube-radius-from: the array's name and, for a .tsf, the file to attach.
struct RadiusSource {
  std::string array;
  std::string tsf;
};

bool endsWith(const std::string& s, std::string_view end) {
  return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
}

RadiusSource radiusSource(const std::string& path, const TubeCliOptions& o) {
  RadiusSource r;
  if (o.radius_from.empty()) return r;
  if (!endsWith(o.radius_from, ".tsf")) {
    r.array = o.radius_from;
    return r;
  }
  if (!endsWith(path, ".tck"))
    throw Error("--tube-radius-from " + o.radius_from + ": a .tsf file needs a .tck input");
  r.tsf = o.radius_from;
  // openTck names the array after the file's stem.
  const size_t slash = r.tsf.find_last_of('/');
  r.array = r.tsf.substr(slash == std::string::npos ? 0 : slash + 1);
  r.array.resize(r.array.size() - 4);
  return r;
}

// Appends streamline i of `chunk`'s array `name` (one component, per point
// or per streamline) to `out`'s array of that name, which it makes at the
// first call; `out` has just received the streamline's points. Throws
// Error when the chunk has no such one-component array.
void copyRadiusData(const Tractogram& chunk, size_t i, const std::string& name, Tractogram& out) {
  const auto find = [&name](const std::vector<DataArray>& arrays) -> const DataArray* {
    for (const DataArray& a : arrays)
      if (a.name == name) return &a;
    return nullptr;
  };
  const auto target = [&name](std::vector<DataArray>& arrays) -> DataArray& {
    for (DataArray& a : arrays)
      if (a.name == name) return a;
    arrays.push_back(DataArray{name, 1, "float32", {}});
    return arrays.back();
  };
  const auto oneComponent = [&name](const DataArray& a) {
    if (a.components != 1)
      throw Error("--tube-radius-from " + name + ": the array has " + std::to_string(a.components) +
                  " components; a radius needs 1");
  };
  if (const DataArray* a = find(chunk.per_point)) {
    oneComponent(*a);
    DataArray& to = target(out.per_point);
    to.values.insert(to.values.end(), a->values.begin() + ptrdiff_t(chunk.offsets[i]),
                     a->values.begin() + ptrdiff_t(chunk.offsets[i + 1]));
  } else if (const DataArray* b = find(chunk.per_streamline)) {
    oneComponent(*b);
    target(out.per_streamline).values.push_back(b->values[i]);
  } else {
    std::string have;
    for (const auto* arrays : {&chunk.per_point, &chunk.per_streamline})
      for (const DataArray& a : *arrays) have += (have.empty() ? "" : ", ") + a.name;
    throw Error("--tube-radius-from " + name + ": the input has no array of that name (it has: " +
                (have.empty() ? std::string("none") : have) + ")");
  }
}

// "A,B" as two finite numbers with A <= B; Error naming the option.
void parsePair(const std::string& text, const char* option, float& a, float& b) {
  std::vector<double> v;
  if (!parseNumberList(text, v) || v.size() != 2 || v[1] < v[0])
    throw Error(std::string(option) + ": expected LO,HI with LO <= HI, got '" + text + "'");
  a = float(v[0]);
  b = float(v[1]);
}

// The radius of `selected`'s array `name` (copied there by copyRadiusData)
// mapped from --tube-radius-data onto --tube-radius-range.
TubeRadius dataRadius(const Tractogram& selected, const std::string& name, const TubeCliOptions& o) {
  TubeRadius r;
  r.array = name;
  const DataArray* a = nullptr;
  for (const DataArray& d : selected.per_point)
    if (d.name == name) a = &d, r.source = TubeRadius::Source::PerPoint;
  for (const DataArray& d : selected.per_streamline)
    if (!a && d.name == name) a = &d, r.source = TubeRadius::Source::PerFiber;
  if (!a) throw Error("--tube-radius-from " + name + ": the input has no array of that name");
  parsePair(o.radius_range, "--tube-radius-range", r.radius_min, r.radius_max);
  if (!(r.radius_min > 0.0f)) throw Error("--tube-radius-range: the radii must be > 0 mm, got '" + o.radius_range + "'");
  if (!o.radius_data.empty()) {
    parsePair(o.radius_data, "--tube-radius-data", r.data_min, r.data_max);
    return r;
  }
  fitRadiusDataRange(r, a->values);
  return r;
}

}  // namespace

void addTubeCliOptions(CLI::App* cmd, TubeCliOptions& o) {
  cmd->add_option(
         "--tubes", o.fibers,
         "Draw these fibers as ray-cast spline tubes over the lines: all, filtered (the filter's kept fibers), or "
         "indices and ranges (0-99,512)")
      ->each([&o](const std::string&) { o.given = true; });
  cmd->add_option("--tube-radius", o.radius_mm, "Tube radius in mm (default 0.5)");
  cmd->add_option("--tube-radius-from", o.radius_from,
                  "Radius from the data: a per-point or per-streamline array of the input (trk scalars or "
                  "properties, TRX dpv or dps), or a .tsf file of a .tck input");
  cmd->add_option("--tube-radius-data", o.radius_data,
                  "LO,HI: the data values mapped onto --tube-radius-range (default: the selected fibers' range)");
  cmd->add_option("--tube-radius-range", o.radius_range, "MIN,MAX: the radii in mm the data range maps to")
      ->capture_default_str();
  cmd->add_flag("--tubes-dim-rest", o.dim_rest,
                "Make the tube fibers the selection: their lines highlighted, the others dimmed (--dim)");
  cmd->add_option(
      "--tube-tolerance", o.resample_tolerance_mm,
      "Resample the tubes' centre lines within this distance of the fibers in mm (default: radius / 20; 0 keeps "
      "every point)");
}

int svoPipelineKind(std::string_view pipeline) {
  for (int k = 0; k < 2; ++k)
    if (pipeline == kSvoPipelineNames[k]) return k;
  return -1;
}

void useSvoTubeDefaults(TubeCliOptions& o) {
  if (o.fibers.empty()) o.fibers = "all";
  if (o.resample_tolerance_mm < 0.0f) o.resample_tolerance_mm = 0.0f;
}

std::vector<float> parseSvoLodPx(const std::string& text) {
  std::vector<double> values;
  const bool ok = parseNumberList(text, values) &&
                  std::all_of(values.begin(), values.end(), [](double v) { return v >= 0.0 && v <= kSvoLodMaxPx; });
  if (!ok)
    throw Error("--svo-lod-px: expected pixels from 0 (off) to " + std::to_string(int(kSvoLodMaxPx)) +
                " (a comma list in bench), got '" + text + "'");
  return std::vector<float>(values.begin(), values.end());
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
  const RadiusSource radius = radiusSource(path, options);
  const auto open = [&]() {
    if (path.empty()) return openPhantom(phantom);
    if (!radius.tsf.empty()) return openTck(path, {radius.tsf});
    return openInput(path);
  };
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
          if (!radius.array.empty()) copyRadiusData(chunk, i, radius.array, selected);
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
  if (radius.array.empty() && selected.pointCount() > 1 && options.radius_mm > extent)
    throw Error("--tube-radius: " + std::to_string(options.radius_mm) +
                " mm is larger than the selected fibers' extent (" + std::to_string(extent) + " mm across)");
  TubeBuildOptions build;
  build.radius.radius = options.radius_mm;
  if (!radius.array.empty()) build.radius = dataRadius(selected, radius.array, options);
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
