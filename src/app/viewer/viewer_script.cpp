#include "app/viewer/viewer_script.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>

#include "app/bundle_output.h"
#include "app/render_options.h"
#include "app/tube_options.h"
#include "core/error.h"
#include "select/cuts.h"
#include "select/number_list.h"
#include "select/region.h"
#include "select/scalar_range.h"

namespace fibscope {
namespace {

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) words.push_back(line.substr(i, j - i));
    i = j;
  }
  return words;
}

double number(std::string_view word, const char* what) {
  const std::string s(word);
  double value = 0;
  char rest = 0;
  if (std::sscanf(s.c_str(), "%lf%c", &value, &rest) != 1 || !std::isfinite(value))
    throw Error(std::string(what) + ": expected a number, got '" + s + "'");
  return value;
}

void expectArguments(const std::vector<std::string_view>& words, size_t min, size_t max, const char* usage) {
  const size_t n = words.size() - 1;
  if (n < min || n > max) throw Error(std::string("expected '") + usage + "', got " + std::to_string(n) + " arguments");
}

bool onOff(std::string_view word, const char* command) {
  if (word == "on") return true;
  if (word == "off") return false;
  throw Error(std::string(command) + ": expected on or off, got '" + std::string(word) + "'");
}

// A length limit in mm, or '-' for none (NaN).
double lengthLimit(std::string_view word, const char* what) {
  if (word == "-") return NAN;
  const double v = number(word, what);
  if (!(v >= 0)) throw Error(std::string(what) + ": expected a length >= 0 mm or -, got " + std::string(word));
  return v;
}

std::string jsonPath(std::string_view word, const char* command) {
  const std::string path(word);
  if (path.size() < 6 || path.substr(path.size() - 5) != ".json")
    throw Error(std::string(command) + ": expected a .json file, got '" + path + "'");
  return path;
}

// The dissection's commands (dissection.h), or nullopt for another name.
std::optional<ViewerAction> parseDissectionCommand(const std::vector<std::string_view>& w) {
  const std::string_view name = w[0];
  if (name == "roi-add") {
    expectArguments(w, 3, 3, "roi-add NAME include|exclude|include_ordered SPEC");
    RoiAddEdit add;
    add.name = std::string(w[1]);
    if (w[2] == "include") add.role = RoiRole::Include;
    else if (w[2] == "exclude") add.role = RoiRole::Exclude;
    else if (w[2] == "include_ordered") add.role = RoiRole::IncludeOrdered;
    else throw Error("roi-add: expected include, exclude or include_ordered, got '" + std::string(w[2]) + "'");
    add.region = parseRegion(w[3]);
    return ViewerAction{DissectionAction{add}};
  }
  if (name == "roi-place") {
    expectArguments(w, 2, 2, "roi-place X Y");
    const double x = number(w[1], "X"), y = number(w[2], "Y");
    if (!(x >= 0 && x < 65536 && y >= 0 && y < 65536))
      throw Error("roi-place: expected window pixels from 0 to 65535, got " + std::string(w[1]) + " " +
                  std::string(w[2]));
    return ViewerAction{RoiPlaceAction{x, y}};
  }
  if (name == "roi-remove") {
    expectArguments(w, 1, 1, "roi-remove NAME");
    return ViewerAction{DissectionAction{RoiRemoveEdit{std::string(w[1])}}};
  }
  if (name == "roi-enable") {
    expectArguments(w, 2, 2, "roi-enable NAME on|off");
    return ViewerAction{DissectionAction{RoiEnableEdit{std::string(w[1]), onOff(w[2], "roi-enable")}}};
  }
  if (name == "ends-only") {
    expectArguments(w, 1, 1, "ends-only on|off");
    return ViewerAction{DissectionAction{EndsOnlyEdit{onOff(w[1], "ends-only")}}};
  }
  if (name == "length") {
    expectArguments(w, 2, 2, "length MIN|- MAX|-");
    const double lo = lengthLimit(w[1], "MIN"), hi = lengthLimit(w[2], "MAX");
    if (lo > hi) throw Error("length: MIN " + std::string(w[1]) + " lies above MAX " + std::string(w[2]));
    return ViewerAction{DissectionAction{LengthEdit{lo, hi}}};
  }
  if (name == "fiber-scalar") {
    expectArguments(w, 3, 3, "fiber-scalar NAME[K] MIN|- MAX|-");
    // The command line's spec, '-' for an open end.
    auto bound = [](std::string_view word) { return word == "-" ? std::string() : std::string(word); };
    ScalarRange range;
    try {
      range = parseScalarRange(std::string(w[1]) + ":" + bound(w[2]) + ":" + bound(w[3]));
    } catch (const Error& e) {
      throw Error(std::string("fiber-scalar: ") + e.what());
    }
    return ViewerAction{DissectionAction{FiberScalarEdit{range}}};
  }
  if (name == "fiber-scalar-clear") {
    expectArguments(w, 0, 0, "fiber-scalar-clear");
    return ViewerAction{DissectionAction{FiberScalarClearEdit{}}};
  }
  if (name == "clip-plane-add") {
    expectArguments(w, 1, 1, "clip-plane-add PX,PY,PZ,NX,NY,NZ");
    return ViewerAction{DissectionAction{ClipPlaneAddEdit{parseClipPlane(w[1])}}};
  }
  if (name == "clip-plane-clear") {
    expectArguments(w, 0, 0, "clip-plane-clear");
    return ViewerAction{DissectionAction{ClipPlaneClearEdit{}}};
  }
  if (name == "cut-mesh-add") {
    expectArguments(w, 1, 1, "cut-mesh-add SPEC:inside|outside");
    return ViewerAction{DissectionAction{CutMeshAddEdit{parseMeshCut(w[1])}}};
  }
  if (name == "cut-mesh-clear") {
    expectArguments(w, 0, 0, "cut-mesh-clear");
    return ViewerAction{DissectionAction{CutMeshClearEdit{}}};
  }
  if (name == "slab") {
    expectArguments(w, 1, 1, "slab MM");
    const double mm = number(w[1], "MM");
    if (!(mm >= 0 && mm <= 1000)) throw Error("slab: expected 0 (none) to 1000 mm, got " + std::string(w[1]));
    return ViewerAction{DissectionAction{SlabEdit{float(mm)}}};
  }
  if (name == "dropped") {
    expectArguments(w, 1, 1, "dropped hide|dim");
    if (w[1] != "hide" && w[1] != "dim")
      throw Error("dropped: expected hide or dim, got '" + std::string(w[1]) + "'");
    return ViewerAction{DissectionAction{DroppedEdit{w[1] == "dim"}}};
  }
  if (name == "roi-save" || name == "roi-load") {
    const bool save = name == "roi-save";
    expectArguments(w, 1, 1, save ? "roi-save FILE.json" : "roi-load FILE.json");
    return ViewerAction{RoiSetFileAction{save, jsonPath(w[1], save ? "roi-save" : "roi-load")}};
  }
  if (name == "export-kept") {
    expectArguments(w, 1, 1, "export-kept OUT.tck|OUT.trk|OUT.trx");
    const std::string path(w[1]);
    auto ends = [&](const char* ext) { return path.size() > 4 && path.substr(path.size() - 4) == ext; };
    if (!ends(".tck") && !ends(".trk") && !ends(".trx"))
      throw Error("export-kept: the output must be a .tck, .trk or .trx file, got '" + path + "'");
    return ViewerAction{ExportKeptAction{path}};
  }
  if (name == "expect-kept") {
    expectArguments(w, 1, 1, "expect-kept N");
    const double n = number(w[1], "N");
    if (!(n >= 0 && n <= 4294967295.0) || n != std::floor(n))
      throw Error("expect-kept: expected a fiber count, got " + std::string(w[1]));
    return ViewerAction{ExpectKeptAction{uint64_t(n), {}}};
  }
  return std::nullopt;
}

std::variant<ViewerAction, WaitFrames, WaitLoaded, WaitExported, WaitBundled> parseCommand(const std::vector<std::string_view>& w) {
  const std::string_view name = w[0];
  if (std::optional<ViewerAction> dissection = parseDissectionCommand(w)) return *dissection;
  if (name == "orbit" || name == "pan") {
    expectArguments(w, 2, 2, name == "orbit" ? "orbit DX DY" : "pan DX DY");
    const double dx = number(w[1], "DX"), dy = number(w[2], "DY");
    if (name == "orbit") return ViewerAction{OrbitAction{dx, dy}};
    return ViewerAction{PanAction{dx, dy}};
  }
  if (name == "dolly") {
    expectArguments(w, 1, 1, "dolly STEPS");
    return ViewerAction{DollyAction{number(w[1], "STEPS")}};
  }
  if (name == "view") {
    expectArguments(w, 1, 1, "view sagittal|coronal|axial|reset");
    return ViewerAction{parseViewName(w[1])};
  }
  if (name == "fov") {
    expectArguments(w, 1, 1, "fov DEG");
    const double deg = number(w[1], "DEG");
    if (!(deg >= 10 && deg <= 90)) throw Error("fov: expected 10 to 90 degrees, got " + std::string(w[1]));
    return ViewerAction{FovAction{deg}};
  }
  if (name == "set") {
    expectArguments(w, 2, 2, "set KEY VALUE");
    RenderSettings scratch;  // checks the value now, not when the line runs
    applySetting(scratch, w[1], w[2]);
    return ViewerAction{SetAction{std::string(w[1]), std::string(w[2])}};
  }
  if (name == "wait") {
    expectArguments(w, 1, 1, "wait FRAMES");
    const double n = number(w[1], "FRAMES");
    if (!(n >= 1 && n <= 100000) || n != std::floor(n))
      throw Error("wait: expected 1 to 100000 frames, got " + std::string(w[1]));
    return WaitFrames{uint32_t(n)};
  }
  if (name == "screenshot") {
    expectArguments(w, 1, 2, "screenshot OUT.png [WxH]");
    ScreenshotAction shot{std::string(w[1])};
    if (shot.path.size() < 5 || shot.path.substr(shot.path.size() - 4) != ".png")
      throw Error("screenshot: the output must be a .png file, got '" + shot.path + "'");
    if (w.size() == 3) parseFrameSize(std::string(w[2]), shot.width, shot.height);
    return ViewerAction{shot};
  }
  if (name == "open") {
    expectArguments(w, 1, 1, "open PATH");
    return ViewerAction{OpenAction{std::string(w[1])}};
  }
  if (name == "wait-loaded") {
    expectArguments(w, 0, 0, "wait-loaded");
    return WaitLoaded{};
  }
  if (name == "pick") {
    expectArguments(w, 2, 3, "pick X Y [add]");
    const double x = number(w[1], "X"), y = number(w[2], "Y");
    if (!(x >= 0 && x < 65536 && y >= 0 && y < 65536))
      throw Error("pick: expected window pixels from 0 to 65535, got " + std::string(w[1]) + " " + std::string(w[2]));
    if (w.size() == 4 && w[3] != "add")
      throw Error("pick: expected 'add' or nothing after X Y, got '" + std::string(w[3]) + "'");
    return ViewerAction{PickAction{x, y, w.size() == 4}};
  }
  if (name == "model") {
    expectArguments(w, 2, 2, "model N show|hide|activate");
    const double n = number(w[1], "N");
    if (!(n >= 0 && n < 65536) || n != std::floor(n))
      throw Error("model: expected a model index from 0 (the first opened), got " + std::string(w[1]));
    ModelAction action;
    action.model = int(n);
    if (w[2] == "show") action.op = ModelAction::Op::Show;
    else if (w[2] == "hide") action.op = ModelAction::Op::Hide;
    else if (w[2] == "activate") action.op = ModelAction::Op::Activate;
    else throw Error("model: expected show, hide or activate, got '" + std::string(w[2]) + "'");
    return ViewerAction{action};
  }
  if (name == "clear-selection") {
    expectArguments(w, 0, 0, "clear-selection");
    return ViewerAction{ClearSelectionAction{}};
  }
  if (name == "export-selection") {
    expectArguments(w, 1, 1, "export-selection OUT.tck");
    const std::string path(w[1]);
    if (path.size() < 5 || path.substr(path.size() - 4) != ".tck")
      throw Error("export-selection: the output must be a .tck file, got '" + path + "'");
    return ViewerAction{ExportSelectionAction{path}};
  }
  if (name == "expect-selected") {
    expectArguments(w, 1, 1, "expect-selected N");
    const double n = number(w[1], "N");
    if (!(n >= 0 && n <= 4294967295.0) || n != std::floor(n))
      throw Error("expect-selected: expected a fiber count, got " + std::string(w[1]));
    return ViewerAction{ExpectSelectedAction{uint64_t(n), {}}};
  }
  if (name == "resize") {
    expectArguments(w, 2, 2, "resize WIDTH HEIGHT");
    const double width = number(w[1], "WIDTH"), height = number(w[2], "HEIGHT");
    if (!(width >= 16 && width <= 16384 && height >= 16 && height <= 16384) || width != std::floor(width) ||
        height != std::floor(height))
      throw Error("resize: expected 16 to 16384 pixels each, got " + std::string(w[1]) + " x " + std::string(w[2]));
    return ViewerAction{ResizeAction{uint32_t(width), uint32_t(height)}};
  }
  if (name == "tubes") {
    expectArguments(w, 1, 7,
                    "tubes selection|filtered|both|all|off [RADIUS_MM] [from=ARRAY|from=] [range=MIN,MAX] "
                    "[svo=straight|curved|off] [voxel=MM] [lod=PX]");
    TubesAction t;
    const std::string_view which = w[1];
    if (which != "selection" && which != "filtered" && which != "both" && which != "all" && which != "off")
      throw Error("tubes: expected selection, filtered, both, all or off, got '" + std::string(which) + "'");
    t.selection = which == "selection" || which == "both";
    t.filtered = which == "filtered" || which == "both";
    t.all = which == "all";
    bool seen[6] = {false, false, false, false, false, false};  // radius, from=, range=, svo=, voxel=, lod=: each once
    for (size_t i = 2; i < w.size(); ++i) {
      const std::string_view word = w[i];
      const int kind = word.starts_with("from=")    ? 1
                       : word.starts_with("range=") ? 2
                       : word.starts_with("svo=")   ? 3
                       : word.starts_with("voxel=") ? 4
                       : word.starts_with("lod=")   ? 5
                                                    : 0;
      if (seen[kind]) throw Error("tubes: '" + std::string(word) + "' repeats an argument");
      seen[kind] = true;
      if (kind == 3) {
        const std::string_view v = word.substr(4);
        if (v != "straight" && v != "curved" && v != "off")
          throw Error("tubes: expected svo=straight, svo=curved or svo=off, got '" + std::string(word) + "'");
        t.svo = v == "straight" ? 1 : (v == "curved" ? 2 : 0);
      } else if (kind == 5) {
        const double lod = number(word.substr(4), "lod=PX");
        if (!(lod >= 0.0 && lod <= double(kSvoLodMaxPx)))
          throw Error("tubes: the octree's level of detail must be 0 to " + std::to_string(int(kSvoLodMaxPx)) +
                      " pixels (0: off)");
        t.svo_lod_px = float(lod);
      } else if (kind == 4) {
        const double voxel = number(word.substr(6), "voxel=MM");
        if (!(voxel >= 0.0 && voxel < 1e6)) throw Error("tubes: the voxel must be >= 0 mm (0: from the data)");
        t.voxel_mm = float(voxel);
      } else if (kind == 1) {
        t.radius_from = std::string(word.substr(5));
      } else if (kind == 2) {
        std::vector<double> range;
        if (!parseNumberList(word.substr(6), range) || range.size() != 2)
          throw Error("tubes: expected range=MIN,MAX in mm");
        t.radius_min = float(range[0]);
        t.radius_max = float(range[1]);
        if (!(t.radius_min > 0.0f) || !(t.radius_max >= t.radius_min))
          throw Error("tubes: the radius range must be > 0 mm and ordered");
      } else {
        t.radius_mm = float(number(word, "RADIUS_MM"));
        if (!(t.radius_mm > 0.0f)) throw Error("tubes: the radius must be > 0 mm");
      }
    }
    return ViewerAction{t};
  }
  if (name == "anatomy") {
    expectArguments(w, 1, 1, "anatomy FILE.nii[.gz]");
    return ViewerAction{AnatomyAction{std::string(w[1])}};
  }
  if (name == "bundle") {
    BundleAction bundle;
    BundleParams& p = bundle.params;
    for (size_t i = 1; i < w.size(); ++i) {
      const size_t eq = w[i].find('=');
      if (eq == std::string_view::npos)
        throw Error("bundle: expected KEY=VALUE, got '" + std::string(w[i]) + "'");
      const std::string_view key = w[i].substr(0, eq), value = w[i].substr(eq + 1);
      if (key == "mode") {
        p.mode = parseBundleMode(std::string(value));
        continue;
      }
      const double v = number(value, std::string(key).c_str());
      if (key == "radius") p.radius = v;
      else if (key == "iterations") {
        if (!(v >= 1 && v <= 1000) || v != std::floor(v))
          throw Error("bundle: iterations: expected 1 to 1000, got " + std::string(value));
        p.iterations = uint32_t(v);
      } else if (key == "voxel") p.voxel_mm = v;
      else if (key == "step") p.step_mm = v;
      else if (key == "smoothing") p.smoothing = v;
      else if (key == "relaxation") p.relaxation = v;
      else if (key == "decay") p.radius_decay = v;
      else if (key == "advection") p.advection = v;
      else if (key == "anisotropy") p.anisotropy = v;
      else if (key == "structure") {
        if (v != 0 && v != 1) throw Error("bundle: structure: expected 0 or 1, got " + std::string(value));
        p.structure_aware = v == 1;
      } else if (key == "structure-power") {
        if (!(v >= 1 && v <= 8) || v != std::floor(v))
          throw Error("bundle: structure-power: expected 1 to 8, got " + std::string(value));
        p.structure_power = uint32_t(v);
      } else if (key == "structure-scale") p.structure_scale = v;
      else
        throw Error("bundle: unknown key '" + std::string(key) +
                    "' (expected radius, iterations, voxel, step, smoothing, relaxation, decay, advection, "
                    "anisotropy, structure, structure-power, structure-scale or mode)");
    }
    try {
      validateBundleParams(p);
    } catch (const Error& e) {
      throw Error(std::string("bundle: ") + e.what());
    }
    return ViewerAction{bundle};
  }
  if (name == "wait-bundle") {
    expectArguments(w, 0, 0, "wait-bundle");
    return WaitBundled{};
  }
  if (name == "show-model" || name == "save-model") {
    const bool save = name == "save-model";
    expectArguments(w, save ? 2 : 1, save ? 2 : 1, save ? "save-model N PATH" : "show-model N");
    const double n = number(w[1], "N");
    if (!(n >= 0 && n < 65536) || n != std::floor(n))
      throw Error(std::string(name) + ": expected a model index from 0 (the first opened), got " + std::string(w[1]));
    if (!save) return ViewerAction{ShowOnlyModelAction{int(n)}};
    const std::string path(w[2]);
    try {
      checkBundledOutputPath(path);
    } catch (const Error& e) {
      throw Error(std::string("save-model: ") + e.what());
    }
    return ViewerAction{SaveModelAction{int(n), path}};
  }
  if (name == "split-view") {
    expectArguments(w, 1, 2, "split-view LEFT RIGHT | split-view off");
    if (w.size() == 2 && w[1] == "off") return ViewerAction{SplitViewAction{}};
    if (w.size() != 3) throw Error("split-view: expected two model indices (LEFT RIGHT) or 'off'");
    SplitViewAction split{true};
    for (const int k : {1, 2}) {
      const double n = number(w[size_t(k)], k == 1 ? "LEFT" : "RIGHT");
      if (!(n >= 0 && n < 65536) || n != std::floor(n))
        throw Error("split-view: expected a model index from 0 (the first opened), got " + std::string(w[size_t(k)]));
      (k == 1 ? split.left : split.right) = int(n);
    }
    return ViewerAction{split};
  }
  if (name == "quit") {
    expectArguments(w, 0, 0, "quit");
    return ViewerAction{QuitAction{}};
  }
  throw Error("unknown command '" + std::string(name) +
              "' (expected orbit, pan, dolly, view, fov, set, wait, wait-loaded, open, model, screenshot, "
              "pick, clear-selection, export-selection, expect-selected, roi-add, roi-place, roi-remove, "
              "roi-enable, ends-only, length, fiber-scalar, fiber-scalar-clear, clip-plane-add, clip-plane-clear, cut-mesh-add, cut-mesh-clear, slab, "
              "dropped, roi-save, roi-load, "
              "export-kept, expect-kept, resize, anatomy, bundle, wait-bundle, show-model, split-view, save-model or quit)");
}

}  // namespace

std::vector<ScriptStep> parseScript(std::string_view text, const std::string& path) {
  std::vector<ScriptStep> steps;
  int line_number = 0;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    ++line_number;
    start = end + 1;
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const std::vector<std::string_view> words = splitWords(line);
    if (words.empty()) continue;
    try {
      steps.push_back({line_number, parseCommand(words)});
      // A failed expectation names the script line it came from.
      if (auto* action = std::get_if<ViewerAction>(&steps.back().command)) {
        if (auto* expect = std::get_if<ExpectSelectedAction>(action))
          expect->where = path + ":" + std::to_string(line_number);
        if (auto* expect = std::get_if<ExpectKeptAction>(action))
          expect->where = path + ":" + std::to_string(line_number);
        // export-kept holds the script until the file is written.
        if (std::holds_alternative<ExportKeptAction>(*action)) steps.push_back({line_number, WaitExported{}});
      }
    } catch (const Error& e) {
      throw Error(path + ":" + std::to_string(line_number) + ": " + e.what());
    }
  }
  return steps;
}

std::vector<ScriptStep> loadScript(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) failErrno(path, "cannot open the script");
  std::ostringstream text;
  text << in.rdbuf();
  return parseScript(text.str(), path);
}

std::vector<ViewerAction> ScriptRunner::nextFrame(bool loading, bool exporting, bool bundling) {
  std::vector<ViewerAction> actions;
  if (waiting_bundled_) {
    if (bundling) return actions;
    waiting_bundled_ = false;
  }
  if (waiting_loaded_) {
    if (loading) return actions;
    waiting_loaded_ = false;
  }
  if (waiting_exported_) {
    if (exporting) return actions;
    waiting_exported_ = false;
  }
  if (waiting_ > 0) {
    --waiting_;
    return actions;
  }
  while (next_ < steps_.size()) {
    const ScriptStep& step = steps_[next_++];
    if (const auto* wait = std::get_if<WaitFrames>(&step.command)) {
      waiting_ = wait->frames - 1;  // this frame is the first one waited
      break;
    }
    if (std::holds_alternative<WaitLoaded>(step.command)) {
      // Checked from the next frame on: an `open` just above is requested
      // when these actions are applied, so the loader is busy by then.
      waiting_loaded_ = true;
      break;
    }
    if (std::holds_alternative<WaitExported>(step.command)) {
      // The export was started by the actions of this frame: checked from
      // the next frame on, as wait-loaded.
      waiting_exported_ = true;
      break;
    }
    if (std::holds_alternative<WaitBundled>(step.command)) {
      // The job was started by the actions of this frame: checked from the
      // next frame on, as wait-loaded.
      waiting_bundled_ = true;
      break;
    }
    const ViewerAction& action = std::get<ViewerAction>(step.command);
    actions.push_back(action);
    if (std::holds_alternative<AnatomyAction>(action) || std::holds_alternative<TubesAction>(action)) {
      // The image is read (the tubes built) while frames go on: the steps
      // after it (a screenshot, a slice setting) see it shown, as after
      // `open` and `wait-loaded`.
      waiting_loaded_ = true;
      break;
    }
  }
  return actions;
}

}  // namespace fibscope
