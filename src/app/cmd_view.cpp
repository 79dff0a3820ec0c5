// `fibscope view [FILE...] [--size WxH] [--screenshot OUT.png --frames N]
// [--script FILE] [--offscreen] [--no-vsync] [--orbit DEG] [--validate] [--device NAME]
// [--phantom-streamlines N] [render settings] [filter criteria: --include ... --roi-set]`:
// the interactive viewer
// (src/app/viewer/). Without a display it renders offscreen, so scripts and
// tests run anywhere Vulkan does.
#include <CLI/CLI.hpp>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/criteria_options.h"
#include "app/open_input.h"
#include "app/viewer/dissection.h"
#include "app/render_options.h"
#include "app/viewer/viewer_app.h"
#include "core/error.h"
#include "select/scalar_range.h"
#include "render/settings_table.h"

namespace fibscope {
namespace {

struct ViewCommandOptions {
  RenderCliOptions render;
  std::vector<std::string> files;
  std::string screenshot;
  uint32_t frames = 0;
  std::string script;
  bool offscreen = false;
  bool no_vsync = false;
  double orbit_deg = 0;
};

// The dissection the viewer starts with: the --roi-set's (its planes and
// slab are in the settings already: renderSettingsFrom), then the command
// line's regions as ROIs, its ends-only and length limits winning, and
// --cut-mesh's cuts after the set's.
RoiSet startingDissection(const CriteriaCliOptions& o, const std::vector<std::string>& cut_meshes) {
  criteriaFrom(o);  // bad specs, lengths or files: one line before any window
  RoiSet set;
  if (!o.roi_set.empty()) {
    set = loadRoiSet(o.roi_set);
    set.clip_planes.clear();
    set.slab.reset();
  }
  auto add = [&](const std::vector<std::string>& specs, RoiRole role, const char* name) {
    for (const std::string& spec : specs)
      set.rois.push_back(Roi{uniqueRoiName(set, name), parseRegion(spec), role, true});
  };
  add(o.include, RoiRole::Include, "include");
  add(o.exclude, RoiRole::Exclude, "exclude");
  add(o.include_ordered, RoiRole::IncludeOrdered, "ordered");
  set.ends_only = set.ends_only || o.ends_only;
  if (!std::isnan(o.min_length)) set.min_length_mm = o.min_length;
  if (!std::isnan(o.max_length)) set.max_length_mm = o.max_length;
  for (const std::string& spec : o.scalar_ranges) {
    const ScalarRange range = parseScalarRange(spec);  // checked by criteriaFrom above
    const int i = findScalarRange(set, range.name, range.component);
    if (i >= 0)
      set.scalar_ranges[size_t(i)] = RoiScalarRange{range, true};
    else
      set.scalar_ranges.push_back(RoiScalarRange{range, true});
  }
  for (const std::string& spec : cut_meshes) {
    try {
      set.cut_meshes.push_back(RoiCutMesh{parseMeshCut(spec), true});
    } catch (const Error& e) {
      throw Error(std::string("--cut-mesh ") + e.what());
    }
  }
  if (enabledCutMeshes(set) > kMaxCutMeshes)
    throw Error("--cut-mesh: at most " + std::to_string(kMaxCutMeshes) + " cut meshes at once, got " +
                std::to_string(enabledCutMeshes(set)));
  return set;
}

void runView(ViewCommandOptions o) {
  ViewerOptions v;
  v.dissection = startingDissection(o.render.criteria, o.render.cut_meshes);
  // A scalar range's array in every file given (the headers alone), as
  // `fibscope filter` checks it, before any window.
  if (!v.dissection.scalar_ranges.empty())
    for (const std::string& file : o.files) {
      std::vector<ScalarRange> ranges;
      for (const RoiScalarRange& r : v.dissection.scalar_ranges)
        if (r.enabled) ranges.push_back(r.range);
      resolveScalarColumns(ranges, openInput(file)->header().per_streamline, file);
    }
  v.dim_dropped = o.render.dim_dropped;
  v.files = o.files;
  v.phantom_streamlines = o.render.phantom_streamlines;
  parseFrameSize(o.render.size, v.width, v.height);
  v.settings = renderSettingsFrom(o.render);
  v.keep_scalar_range = o.render.gave("scalar-range");
  v.anatomy = o.render.anatomy;
  for (const SettingInfo& info : renderSettingsTable())
    if (o.render.gave(info.name)) v.given_settings.insert(std::string(info.name));
  if (!o.screenshot.empty() && (o.screenshot.size() < 5 || o.screenshot.substr(o.screenshot.size() - 4) != ".png"))
    throw Error("--screenshot: the output must be a .png file, got '" + o.screenshot + "'");
  v.screenshot = o.screenshot;
  v.frames = o.frames;
  // A screenshot run stops by itself: one frame unless told otherwise.
  if (!v.screenshot.empty() && v.frames == 0 && o.script.empty()) v.frames = 1;
  v.script = o.script;
  v.offscreen = o.offscreen;
  v.vsync = !o.no_vsync;
  if (!(o.orbit_deg >= -90 && o.orbit_deg <= 90))
    throw Error("--orbit: expected degrees per frame in [-90, 90], got " + std::to_string(o.orbit_deg));
  v.orbit_deg_per_frame = o.orbit_deg;
  v.validate = o.render.validate;
  v.device = o.render.device;
  runViewer(v);
}

}  // namespace

void addViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewCommandOptions>();
  o->render.size = "1280x800";
  o->render.defaults.orientation_labels = true;  // --no-orientation-labels
  CLI::App* cmd = app.add_subcommand("view", "Open the interactive viewer on tractograms (none: the built-in phantom)");
  addRenderCliOptions(cmd, o->render);
  // The viewer opens several files: the positional takes them all.
  cmd->remove_option(cmd->get_option("input"));
  cmd->add_option("files", o->files, "Tractograms (.tck .trk .trk.gz .tt.gz .trx .vtk .vtp .fbl); none: the built-in phantom");
  cmd->add_option("--screenshot", o->screenshot, "Write the window (panels included) to this PNG after the last frame");
  cmd->add_option("--frames", o->frames, "Render this many frames, then exit");
  cmd->add_option("--script", o->script, "Run viewer commands from this file (one a line)");
  cmd->add_flag("--offscreen", o->offscreen, "No window: render into an offscreen image");
  cmd->add_flag("--no-vsync", o->no_vsync, "Present without waiting for vertical sync (mailbox or immediate)");
  cmd->add_option("--orbit", o->orbit_deg,
                  "Turn the camera this many degrees per frame about the view's up axis (the fiblets paper's "
                  "benchmark turns 1.14); the frame times are printed at exit");
  cmd->callback([o] { runView(*o); });
}

}  // namespace fibscope
