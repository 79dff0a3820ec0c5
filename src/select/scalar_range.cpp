#include "select/scalar_range.h"

#include <charconv>
#include <cstdio>

#include "core/error.h"

namespace fibscope {
namespace {

// The largest component a spec may name: arrays have a few (rgb: 3, a
// tensor: 9); this only bounds the integer read.
constexpr uint32_t kMaxComponent = 1u << 16;

bool parseNumber(std::string_view text, double& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size() && std::isfinite(out);
}

// The shortest text that reads back as the same double.
std::string number(double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, end) : std::to_string(v);
}

}  // namespace

ScalarRange parseScalarRange(std::string_view spec) {
  const std::string quoted = "\"" + std::string(spec) + "\"";
  auto bad = [&](const std::string& what) -> ScalarRange {
    throw Error(quoted + ": " + what + " (expected NAME:MIN:MAX or NAME[K]:MIN:MAX, MIN or MAX empty for an open end)");
  };
  const size_t last = spec.rfind(':');
  if (last == std::string_view::npos || last == 0) return bad("no NAME:MIN:MAX");
  const size_t middle = spec.rfind(':', last - 1);
  if (middle == std::string_view::npos) return bad("no NAME:MIN:MAX");
  ScalarRange r;
  std::string_view name = spec.substr(0, middle);
  if (name.ends_with(']')) {
    const size_t open = name.rfind('[');
    if (open == std::string_view::npos) return bad("a ']' without '['");
    const std::string_view digits = name.substr(open + 1, name.size() - open - 2);
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), r.component);
    if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() || r.component > kMaxComponent)
      return bad("component \"" + std::string(digits) + "\" is not an integer from 0 to " +
                 std::to_string(kMaxComponent));
    name = name.substr(0, open);
  }
  if (name.empty()) return bad("no array name");
  r.name = std::string(name);
  const std::string_view lo = spec.substr(middle + 1, last - middle - 1), hi = spec.substr(last + 1);
  if (!lo.empty() && !parseNumber(lo, r.min)) return bad("MIN \"" + std::string(lo) + "\" is not a finite number");
  if (!hi.empty() && !parseNumber(hi, r.max)) return bad("MAX \"" + std::string(hi) + "\" is not a finite number");
  checkScalarRange(r, quoted);
  return r;
}

void checkScalarRange(const ScalarRange& r, const std::string& what) {
  if (std::isinf(r.min) || std::isinf(r.max)) throw Error(what + ": a bound is infinite (leave it empty for an open end)");
  if (r.min > r.max) throw Error(what + ": MIN " + number(r.min) + " is above MAX " + number(r.max));
}

std::string scalarRangeArray(const ScalarRange& r) {
  // A name that ends in "]" itself keeps its "[0]": "a[2]" alone would read
  // back as component 2 of "a" (found by fuzz_specs).
  return r.component == 0 && !r.name.ends_with(']') ? r.name : r.name + "[" + std::to_string(r.component) + "]";
}

std::string scalarRangeSpec(const ScalarRange& r) {
  return scalarRangeArray(r) + ":" + (std::isnan(r.min) ? "" : number(r.min)) + ":" +
         (std::isnan(r.max) ? "" : number(r.max));
}

std::string scalarRangeOutside(const ScalarRange& r) {
  return scalarRangeArray(r) + " outside [" + (std::isnan(r.min) ? "-inf" : number(r.min)) + ", " +
         (std::isnan(r.max) ? "inf" : number(r.max)) + "]";
}

std::string arrayNamesList(std::span<const DataArray> arrays) {
  if (arrays.empty()) return "none";
  std::string out;
  for (const DataArray& a : arrays) {
    if (!out.empty()) out += ", ";
    out += a.components > 1 ? a.name + "[" + std::to_string(a.components) + "]" : a.name;
  }
  return out;
}

std::vector<ScalarColumn> resolveScalarColumns(std::span<const ScalarRange> ranges,
                                               std::span<const DataArray> arrays, const std::string& path) {
  std::vector<ScalarColumn> out;
  for (const ScalarRange& r : ranges) {
    size_t a = 0;
    while (a < arrays.size() && arrays[a].name != r.name) ++a;
    if (a == arrays.size())
      fail(path, "no per-streamline array \"" + r.name + "\" for the scalar range " + scalarRangeSpec(r) +
                     " (its per-streamline arrays: " + arrayNamesList(arrays) + ")");
    if (r.component >= arrays[a].components)
      fail(path, "per-streamline array \"" + r.name + "\" has " + std::to_string(arrays[a].components) +
                     " component" + (arrays[a].components == 1 ? "" : "s") + ", no [" + std::to_string(r.component) +
                     "] for the scalar range " + scalarRangeSpec(r) + " (its per-streamline arrays: " +
                     arrayNamesList(arrays) + ")");
    out.push_back({a, r.component});
  }
  return out;
}

namespace {

void appendValues(const Tractogram& t, std::span<const ScalarColumn> columns, std::vector<std::vector<float>>& out) {
  for (size_t r = 0; r < columns.size(); ++r) {
    const DataArray& a = t.per_streamline[columns[r].array];
    for (size_t s = 0; s < t.streamlineCount(); ++s) out[r].push_back(a.values[s * a.components + columns[r].component]);
  }
}

}  // namespace

std::vector<std::vector<float>> scalarValues(const Tractogram& t, std::span<const ScalarRange> ranges,
                                             const std::string& path) {
  std::vector<std::vector<float>> out(ranges.size());
  appendValues(t, resolveScalarColumns(ranges, t.per_streamline, path), out);
  return out;
}

std::vector<std::vector<float>> readScalarValues(TractogramReader& reader, std::span<const ScalarRange> ranges) {
  const std::string& path = reader.header().path;
  resolveScalarColumns(ranges, reader.header().per_streamline, path);
  std::vector<std::vector<float>> out(ranges.size());
  Tractogram chunk;
  while (reader.read(chunk, size_t(1) << 20)) appendValues(chunk, resolveScalarColumns(ranges, chunk.per_streamline, path), out);
  return out;
}

}  // namespace fibscope
