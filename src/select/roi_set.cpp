#include "select/roi_set.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>

#include "core/error.h"
#include "core/output_file.h"
#include "select/cut_mesh.h"

namespace fibscope {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr uint64_t kMaxRoiSetBytes = 16u << 20;  // a set is a few kB; refuse to parse a stray large file
constexpr int kMaxDepth = 8;                     // the schema nests 3 deep

const char* typeName(const json& v) {
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_boolean()) return "true or false";
  if (v.is_array()) return "an array";
  if (v.is_object()) return "an object";
  return "null";
}

// Reads one set file, naming the place of whatever is wrong.
class SetReader {
 public:
  explicit SetReader(const std::string& path) : path_(path), folder_(fs::path(path).parent_path().string()) {}

  [[noreturn]] void failAt(const std::string& place, const std::string& what) const {
    fail(path_, place.empty() ? what : place + ": " + what);
  }
  static std::string in(const std::string& place, const std::string& key) {
    return place.empty() ? key : place + "." + key;
  }

  // An object whose keys are all among `allowed`.
  void checkKeys(const json& v, const std::string& place, std::initializer_list<const char*> allowed) const {
    if (!v.is_object()) failAt(place, std::string("expected an object, found ") + typeName(v));
    for (const auto& item : v.items()) {
      const std::string& key = item.key();
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* k) { return key == k; }))
        failAt(place, "unknown key \"" + key + "\"");
    }
  }
  const json* find(const json& object, const char* key) const {
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }
  const json& require(const json& object, const std::string& place, const char* key) const {
    const json* v = find(object, key);
    if (!v) failAt(place, std::string("missing key \"") + key + "\"");
    return *v;
  }
  bool boolean(const json& v, const std::string& place) const {
    if (!v.is_boolean()) failAt(place, std::string("expected true or false, found ") + typeName(v));
    return v.get<bool>();
  }
  std::string string(const json& v, const std::string& place) const {
    if (!v.is_string()) failAt(place, std::string("expected a string, found ") + typeName(v));
    return v.get<std::string>();
  }
  double number(const json& v, const std::string& place) const {
    if (!v.is_number()) failAt(place, std::string("expected a number, found ") + typeName(v));
    return v.get<double>();
  }
  glm::vec3 vec3(const json& v, const std::string& place) const {
    if (!v.is_array() || v.size() != 3) failAt(place, "expected [x, y, z] (3 numbers, mm)");
    glm::vec3 out;
    for (int k = 0; k < 3; ++k) {
      out[k] = float(number(v[size_t(k)], place + "[" + std::to_string(k) + "]"));
      if (!std::isfinite(out[k])) failAt(place, "a coordinate beyond a float's range");
    }
    return out;
  }
  const json& array(const json& v, const std::string& place) const {
    if (!v.is_array()) failAt(place, std::string("expected an array, found ") + typeName(v));
    return v;
  }
  std::string resolve(const std::string& p) const { return pathAgainstFolder(p, folder_, true); }
  const std::string& path() const { return path_; }
  const std::string& folder() const { return folder_; }

 private:
  std::string path_, folder_;
};

Roi readRoi(const SetReader& r, const json& v, const std::string& place) {
  r.checkKeys(v, place, {"name", "region", "role", "enabled"});
  Roi roi;
  if (const json* name = r.find(v, "name")) roi.name = r.string(*name, place + ".name");
  const std::string region_place = place + ".region";
  const std::string spec =
      regionSpecAgainstFolder(r.string(r.require(v, place, "region"), region_place), r.folder(), true);
  try {
    roi.region = parseRegion(spec);
  } catch (const Error& e) {
    r.failAt(region_place, e.what());
  }
  if (const json* role = r.find(v, "role")) {
    const std::string text = r.string(*role, place + ".role");
    if (text == "include")
      roi.role = RoiRole::Include;
    else if (text == "exclude")
      roi.role = RoiRole::Exclude;
    else if (text == "include_ordered")
      roi.role = RoiRole::IncludeOrdered;
    else
      r.failAt(place + ".role", "expected \"include\", \"exclude\" or \"include_ordered\", found \"" + text + "\"");
  }
  if (const json* enabled = r.find(v, "enabled")) roi.enabled = r.boolean(*enabled, place + ".enabled");
  return roi;
}

RoiScalarRange readScalarRange(const SetReader& r, const json& v, const std::string& place) {
  r.checkKeys(v, place, {"name", "component", "min", "max", "enabled"});
  RoiScalarRange out;
  out.range.name = r.string(r.require(v, place, "name"), place + ".name");
  if (out.range.name.empty()) r.failAt(place + ".name", "empty (expected a per-streamline array's name)");
  if (const json* c = r.find(v, "component")) {
    if (!c->is_number_unsigned() || c->get<uint64_t>() > 65536)
      r.failAt(place + ".component", "expected an integer from 0 to 65536, found " + oneLine(c->dump()));
    out.range.component = c->get<uint32_t>();
  }
  for (const auto& [key, member] : {std::pair{"min", &out.range.min}, std::pair{"max", &out.range.max}})
    if (const json* b = r.find(v, key)) {
      *member = r.number(*b, place + "." + key);
      if (!std::isfinite(*member)) r.failAt(place + "." + key, "not a finite number");
    }
  if (out.range.min > out.range.max)
    r.failAt(place, "min " + oneLine(v["min"].dump()) + " is above max " + oneLine(v["max"].dump()));
  if (const json* enabled = r.find(v, "enabled")) out.enabled = r.boolean(*enabled, place + ".enabled");
  return out;
}

RoiClipPlane readClipPlane(const SetReader& r, const json& v, const std::string& place) {
  r.checkKeys(v, place, {"point", "normal", "enabled"});
  RoiClipPlane out;
  const glm::vec3 point = r.vec3(r.require(v, place, "point"), place + ".point");
  const glm::vec3 normal = r.vec3(r.require(v, place, "normal"), place + ".normal");
  out.plane = makeClipPlane(point, normal, r.path() + ": " + place);
  if (const json* enabled = r.find(v, "enabled")) out.enabled = r.boolean(*enabled, place + ".enabled");
  return out;
}

RoiCutMesh readCutMesh(const SetReader& r, const json& v, const std::string& place) {
  r.checkKeys(v, place, {"mesh", "cull", "enabled"});
  RoiCutMesh out;
  std::string spec = r.string(r.require(v, place, "mesh"), place + ".mesh");
  if (spec.empty()) r.failAt(place + ".mesh", "empty (expected an OBJ file or a built-in shape)");
  if (isBuiltinMeshSpec(spec)) {
    try {
      cutMeshFromSpec(spec);
    } catch (const Error& e) {
      r.failAt(place + ".mesh", e.what());
    }
  } else {
    spec = r.resolve(spec);
  }
  const std::string cull = r.string(r.require(v, place, "cull"), place + ".cull");
  if (cull != "inside" && cull != "outside")
    r.failAt(place + ".cull", "expected \"inside\" or \"outside\" (the side culled), found \"" + cull + "\"");
  out.cut = {spec, cull == "inside"};
  if (const json* enabled = r.find(v, "enabled")) out.enabled = r.boolean(*enabled, place + ".enabled");
  return out;
}

Slab readSlab(const SetReader& r, const json& v, const std::string& place) {
  r.checkKeys(v, place, {"thickness_mm", "follow"});
  Slab slab;
  const double t = r.number(r.require(v, place, "thickness_mm"), place + ".thickness_mm");
  slab.thickness_mm = float(t);
  if (!(t > 0 && slab.thickness_mm > 0 && std::isfinite(slab.thickness_mm)))
    r.failAt(place + ".thickness_mm", "a slab's thickness must be > 0 mm");
  if (const json* follow = r.find(v, "follow")) {
    slab.follow = r.string(*follow, place + ".follow");
    if (!isSlabFollow(slab.follow))
      r.failAt(place + ".follow",
               "expected \"axial\", \"coronal\", \"sagittal\" or \"\", found \"" + slab.follow + "\"");
  }
  return slab;
}

// Parses JSON refusing repeated keys (nlohmann keeps the last one silently)
// and nesting deeper than the schema could need.
json parseStrict(const std::string& text, const std::string& path) {
  std::vector<std::set<std::string>> keys;  // of each open object
  json::parser_callback_t check = [&](int depth, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) {
      if (depth >= kMaxDepth) fail(path, "JSON nests deeper than " + std::to_string(kMaxDepth) + " levels");
      if (event == json::parse_event_t::object_start) keys.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      if (!keys.empty()) keys.pop_back();
    } else if (event == json::parse_event_t::key && !keys.empty()) {
      const std::string key = parsed.get<std::string>();
      if (!keys.back().insert(key).second) fail(path, "repeated key \"" + key + "\" in one object");
    }
    return true;
  };
  try {
    return json::parse(text, check);
  } catch (const json::exception& e) {
    // parse_error, and out_of_range.406 for a number beyond double's range
    // (1e999), which escaped as a crash before.
    std::string what = e.what();
    if (const size_t bracket = what.find("] "); what.starts_with("[json.exception") && bracket != std::string::npos)
      what = what.substr(bracket + 2);
    fail(path, "invalid JSON: " + oneLine(what));
  }
}

// The shortest decimal that reads back as the same float, as a JSON number.
json floatValue(float v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  double d = v;
  if (ec == std::errc()) std::from_chars(buf, end, d);
  return d;
}

json vec3Value(const glm::vec3& v) { return json::array({floatValue(v.x), floatValue(v.y), floatValue(v.z)}); }

}  // namespace

const char* roiRoleName(RoiRole role) {
  switch (role) {
    case RoiRole::Include:
      return "include";
    case RoiRole::Exclude:
      return "exclude";
    case RoiRole::IncludeOrdered:
      return "include_ordered";
  }
  return "include";
}

std::string pathAgainstFolder(const std::string& path, const std::string& folder, bool resolve) {
  const fs::path p(path);
  if (resolve) return p.is_absolute() || folder.empty() ? path : (fs::path(folder) / p).lexically_normal().string();
  std::error_code ec;
  const fs::path absolute = fs::absolute(p, ec).lexically_normal();
  fs::path base = fs::absolute(folder.empty() ? fs::path(".") : fs::path(folder), ec).lexically_normal();
  if (base.has_parent_path() && base.filename().empty()) base = base.parent_path();  // "/a/b/" -> "/a/b"
  const fs::path relative = absolute.lexically_relative(base);
  if (!relative.empty() && *relative.begin() != ".." && relative != ".") return relative.string();
  return absolute.string();
}

std::string regionSpecAgainstFolder(const std::string& spec, const std::string& folder, bool resolve) {
  constexpr std::string_view kMask = "mask:";
  if (!spec.starts_with(kMask) || spec.size() == kMask.size()) return spec;
  return std::string(kMask) + pathAgainstFolder(spec.substr(kMask.size()), folder, resolve);
}

RoiSet parseRoiSet(const std::string& text, const std::string& path) {
  const SetReader r(path);
  const json doc = parseStrict(text, path);
  if (!doc.is_object()) r.failAt("", std::string("expected a JSON object, found ") + typeName(doc));
  const json* version = r.find(doc, "fibscope_roi_set");
  if (!version) r.failAt("", "missing \"fibscope_roi_set\": 1 (not a fibscope ROI set?)");
  if (!version->is_number_integer() || version->get<int64_t>() != kRoiSetVersion)
    r.failAt("fibscope_roi_set", "version " + oneLine(version->dump()) + " (this fibscope reads version " +
                                     std::to_string(kRoiSetVersion) + ")");
  r.checkKeys(doc, "",
              {"fibscope_roi_set", "rois", "ends_only", "min_length_mm", "max_length_mm", "scalar_ranges",
               "clip_planes", "slab", "cut_meshes", "anatomy"});
  RoiSet set;
  if (const json* rois = r.find(doc, "rois"))
    for (size_t i = 0; i < r.array(*rois, "rois").size(); ++i)
      set.rois.push_back(readRoi(r, (*rois)[i], "rois[" + std::to_string(i) + "]"));
  if (const json* v = r.find(doc, "ends_only")) set.ends_only = r.boolean(*v, "ends_only");
  for (const auto& [key, member] :
       {std::pair{"min_length_mm", &set.min_length_mm}, std::pair{"max_length_mm", &set.max_length_mm}})
    if (const json* v = r.find(doc, key)) {
      *member = r.number(*v, key);
      if (!(*member >= 0)) r.failAt(key, "a length must be >= 0 mm");
    }
  if (set.min_length_mm > set.max_length_mm)
    r.failAt("min_length_mm", "above max_length_mm (" + oneLine(doc["min_length_mm"].dump()) + " > " +
                                  oneLine(doc["max_length_mm"].dump()) + ")");
  if (const json* ranges = r.find(doc, "scalar_ranges")) {
    for (size_t i = 0; i < r.array(*ranges, "scalar_ranges").size(); ++i)
      set.scalar_ranges.push_back(readScalarRange(r, (*ranges)[i], "scalar_ranges[" + std::to_string(i) + "]"));
    const auto enabled = std::count_if(set.scalar_ranges.begin(), set.scalar_ranges.end(),
                                       [](const RoiScalarRange& s) { return s.enabled; });
    if (size_t(enabled) > FiberFilter::kMaxScalarRanges)
      r.failAt("scalar_ranges", std::to_string(enabled) + " enabled (at most " +
                                    std::to_string(FiberFilter::kMaxScalarRanges) + " at once)");
  }
  if (const json* planes = r.find(doc, "clip_planes")) {
    for (size_t i = 0; i < r.array(*planes, "clip_planes").size(); ++i)
      set.clip_planes.push_back(readClipPlane(r, (*planes)[i], "clip_planes[" + std::to_string(i) + "]"));
    const auto enabled =
        std::count_if(set.clip_planes.begin(), set.clip_planes.end(), [](const RoiClipPlane& p) { return p.enabled; });
    if (size_t(enabled) > kMaxClipPlanes)
      r.failAt("clip_planes",
               std::to_string(enabled) + " enabled (at most " + std::to_string(kMaxClipPlanes) + " at once)");
  }
  if (const json* slab = r.find(doc, "slab")) set.slab = readSlab(r, *slab, "slab");
  if (const json* meshes = r.find(doc, "cut_meshes"))
    for (size_t i = 0; i < r.array(*meshes, "cut_meshes").size(); ++i)
      set.cut_meshes.push_back(readCutMesh(r, (*meshes)[i], "cut_meshes[" + std::to_string(i) + "]"));
  if (const json* anatomy = r.find(doc, "anatomy")) {
    set.anatomy = r.string(*anatomy, "anatomy");
    if (set.anatomy.empty()) r.failAt("anatomy", "empty (expected a NIfTI file)");
    set.anatomy = r.resolve(set.anatomy);
  }
  return set;
}

RoiSet loadRoiSet(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) fail(path, fs::exists(path, ec) ? "not a regular file" : "no such file");
  const uint64_t bytes = fs::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (bytes > kMaxRoiSetBytes)
    fail(path,
         std::to_string(bytes) + " bytes: too large for a ROI set (" + std::to_string(kMaxRoiSetBytes) + " at most)");
  std::ifstream in(path, std::ios::binary);
  if (!in) failErrno(path, "cannot open");
  std::string text(bytes, '\0');
  if (!in.read(text.data(), std::streamsize(bytes))) fail(path, "could not read all of its bytes");
  return parseRoiSet(text, path);
}

std::string roiSetJson(const RoiSet& set, const std::string& path) {
  const std::string folder = fs::path(path).parent_path().string();
  nlohmann::ordered_json doc;
  doc["fibscope_roi_set"] = kRoiSetVersion;
  doc["rois"] = nlohmann::ordered_json::array();
  for (const Roi& roi : set.rois)
    doc["rois"].push_back({{"name", roi.name},
                           {"region", regionSpecAgainstFolder(regionSpec(roi.region), folder, false)},
                           {"role", roiRoleName(roi.role)},
                           {"enabled", roi.enabled}});
  doc["ends_only"] = set.ends_only;
  if (!std::isnan(set.min_length_mm)) doc["min_length_mm"] = set.min_length_mm;
  if (!std::isnan(set.max_length_mm)) doc["max_length_mm"] = set.max_length_mm;
  if (!set.scalar_ranges.empty()) {
    doc["scalar_ranges"] = nlohmann::ordered_json::array();
    for (const RoiScalarRange& s : set.scalar_ranges) {
      nlohmann::ordered_json entry = {{"name", s.range.name}, {"component", s.range.component}};
      if (!std::isnan(s.range.min)) entry["min"] = s.range.min;
      if (!std::isnan(s.range.max)) entry["max"] = s.range.max;
      entry["enabled"] = s.enabled;
      doc["scalar_ranges"].push_back(std::move(entry));
    }
  }
  doc["clip_planes"] = nlohmann::ordered_json::array();
  for (const RoiClipPlane& p : set.clip_planes)
    doc["clip_planes"].push_back(
        {{"point", vec3Value(p.plane.point)}, {"normal", vec3Value(p.plane.normal)}, {"enabled", p.enabled}});
  if (set.slab) doc["slab"] = {{"thickness_mm", floatValue(set.slab->thickness_mm)}, {"follow", set.slab->follow}};
  doc["cut_meshes"] = nlohmann::ordered_json::array();
  for (const RoiCutMesh& m : set.cut_meshes)
    doc["cut_meshes"].push_back(
        {{"mesh", isBuiltinMeshSpec(m.cut.spec) ? m.cut.spec : pathAgainstFolder(m.cut.spec, folder, false)},
         {"cull", m.cut.cull_inside ? "inside" : "outside"},
         {"enabled", m.enabled}});
  if (!set.anatomy.empty()) doc["anatomy"] = pathAgainstFolder(set.anatomy, folder, false);
  try {
    return doc.dump(2) + "\n";
  } catch (const nlohmann::ordered_json::type_error&) {
    fail(path, "a name or path is not valid UTF-8 text");
  }
}

void saveRoiSet(const RoiSet& set, const std::string& path) {
  const std::string text = roiSetJson(set, path);
  OutputFile out(path, /*overwrite=*/true);
  out.write(text);
  out.commit();
}

FilterCriteria filterCriteria(const RoiSet& set) {
  FilterCriteria c;
  for (const Roi& roi : set.rois) {
    if (!roi.enabled) continue;
    switch (roi.role) {
      case RoiRole::Include:
        c.include.push_back(roi.region);
        break;
      case RoiRole::Exclude:
        c.exclude.push_back(roi.region);
        break;
      case RoiRole::IncludeOrdered:
        c.include_ordered.push_back(roi.region);
        break;
    }
  }
  c.ends_only = set.ends_only;
  c.min_length_mm = set.min_length_mm;
  c.max_length_mm = set.max_length_mm;
  for (const RoiScalarRange& s : set.scalar_ranges)
    if (s.enabled) c.scalar_ranges.push_back(s.range);
  return c;
}

CutSet cutSet(const RoiSet& set) {
  CutSet cuts;
  for (const RoiClipPlane& p : set.clip_planes)
    if (p.enabled) cuts.planes.push_back(p.plane);
  cuts.slab = set.slab;
  for (const RoiCutMesh& m : set.cut_meshes)
    if (m.enabled) cuts.meshes.push_back(m.cut);
  return cuts;
}

FilterCriteria mergeCriteria(FilterCriteria set, const FilterCriteria& command_line) {
  auto append = [](std::vector<Region>& to, const std::vector<Region>& from) {
    to.insert(to.end(), from.begin(), from.end());
  };
  append(set.include, command_line.include);
  append(set.include_ordered, command_line.include_ordered);
  append(set.exclude, command_line.exclude);
  set.ends_only = set.ends_only || command_line.ends_only;
  if (!std::isnan(command_line.min_length_mm)) set.min_length_mm = command_line.min_length_mm;
  if (!std::isnan(command_line.max_length_mm)) set.max_length_mm = command_line.max_length_mm;
  set.scalar_ranges.insert(set.scalar_ranges.end(), command_line.scalar_ranges.begin(),
                           command_line.scalar_ranges.end());
  // (A set holds no distance zone: the command line's is the only one.)
  set.distance_zone = command_line.distance_zone;
  set.max_distance_mm = command_line.max_distance_mm;
  return set;
}

}  // namespace fibscope
