#include "app/render_options.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.h"
#include "render/clip_planes.h"
#include "render/colormap.h"
#include "select/cuts.h"
#include "select/roi_set.h"
#include "render/settings_table.h"

namespace fibscope {

bool RenderCliOptions::gave(std::string_view name) const {
  const auto v = values.find(name);
  if (v != values.end() && !v->second.empty()) return true;
  const auto f = flags.find(name);
  return f != flags.end() && f->second;
}

namespace {

// A flag on by default is turned off by --no-NAME.
bool negatedFlag(const SettingInfo& info, const RenderSettings& defaults) {
  return info.kind == SettingKind::Flag && defaults.*info.flag;
}

}  // namespace

void addRenderCliOptions(CLI::App* cmd, RenderCliOptions& o) {
  cmd->add_option("input", o.input, "Tractogram (.tck .trk .trk.gz .tt.gz .trx .vtk .vtp .fbl); none: the built-in phantom");
  cmd->add_option("--phantom-streamlines", o.phantom_streamlines, "Streamlines of the built-in phantom")
      ->capture_default_str();
  cmd->add_option("--size", o.size, "Frame size WxH in pixels")->capture_default_str();
  for (const SettingInfo& info : renderSettingsTable()) {
    const std::string name(info.name);
    if (info.kind == SettingKind::Flag) {
      const bool negated = negatedFlag(info, o.defaults);
      cmd->add_flag((negated ? "--no-" : "--") + name, o.flags[name],
                    (negated ? "No " : "") + std::string(info.help) + (negated ? " (on by default)" : ""));
    } else {
      cmd->add_option("--" + name, o.values[name],
                      std::string(info.help) + " [" + settingExpectation(info) + "; default " +
                          settingText(o.defaults, info) + "]");
    }
  }
  addCriteriaCliOptions(cmd, o.criteria);
  cmd->add_option("--clip-plane", o.clip_planes,
                  "Draw only the side of the plane through PX,PY,PZ that the normal NX,NY,NZ points to (mm); "
                  "fibers are clipped at the plane; repeatable, at most 6");
  cmd->add_option("--cut-mesh", o.cut_meshes,
                  "Hide what lies inside (SPEC:inside) or outside (SPEC:outside) a closed mesh, per pixel: SPEC is "
                  "an OBJ file or box:X0,Y0,Z0,X1,Y1,Z1, obox:... or sphere:X,Y,Z,R; repeatable, at most 4");
  cmd->add_option("--anatomy", o.anatomy,
                  "NIfTI volume (.nii, .nii.gz: T1, FA, ...) shown as its three voxel-plane slices (--slice-i/j/k, "
                  "--anatomy-range, --anatomy-opacity)");
  cmd->add_flag("--dim-dropped", o.dim_dropped,
                "Draw the fibers the criteria drop dimmed (the kept ones highlighted) instead of hiding them");
  cmd->add_option("--device", o.device, "Vulkan device whose name contains this");
  cmd->add_flag("--validate", o.validate, "Vulkan validation layers on; any message is an error");
}

void parseFrameSize(const std::string& text, uint32_t& width, uint32_t& height) {
  unsigned long w = 0, h = 0;
  char x = 0, rest = 0;
  if (std::sscanf(text.c_str(), "%lu%c%lu%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X') || w < 1 ||
      h < 1 || w > 16384 || h > 16384)
    throw Error("--size: expected WxH with 1 to 16384 pixels each (e.g. 1920x1080), got '" + text + "'");
  width = uint32_t(w);
  height = uint32_t(h);
}

RenderSettings renderSettingsFrom(const RenderCliOptions& o) {
  RenderSettings s = o.defaults;
  for (const SettingInfo& info : renderSettingsTable()) {
    const std::string name(info.name);
    if (info.kind == SettingKind::Flag) {
      const auto f = o.flags.find(name);
      if (f != o.flags.end() && f->second) s.*info.flag = !negatedFlag(info, o.defaults);
      continue;
    }
    const auto v = o.values.find(name);
    if (v != o.values.end() && !v->second.empty()) setSetting(s, info, v->second, "--" + name);
  }
  auto addPlane = [&](const ClipPlane& p) {
    s.clip_planes.push_back(planeThrough({p.point.x, p.point.y, p.point.z}, {p.normal.x, p.normal.y, p.normal.z}));
  };
  if (!o.criteria.roi_set.empty()) {
    // The set's cuts; the command line's planes come after them and its
    // --slab wins.
    const CutSet cuts = cutSet(loadRoiSet(o.criteria.roi_set));
    for (const ClipPlane& p : cuts.planes) addPlane(p);
    if (cuts.slab && !o.gave("slab")) s.slab_mm = cuts.slab->thickness_mm;
  }
  for (const std::string& spec : o.clip_planes) {
    try {
      addPlane(parseClipPlane(spec));
    } catch (const Error& e) {
      throw Error(std::string("--clip-plane ") + e.what());
    }
  }
  if (s.clip_planes.size() > shader::kMaxClipPlanes)
    throw Error("--clip-plane: at most " + std::to_string(shader::kMaxClipPlanes) + " planes, got " +
                std::to_string(s.clip_planes.size()));
  return s;
}

void applyScalarColoring(const gpu::VulkanContext& context, const GpuDataset& dataset, const RenderCliOptions& o,
                         RenderSettings& settings, GpuScene& scene) {
  if (settings.color != ColorMode::Scalar) return;
  const uint32_t fibers = dataset.block().fiber_count;
  if (fibers == 0) return;
  scene.fiber_scalars = dataset.fiberLength().address;
  if (o.gave("scalar-range")) return;
  std::vector<float> lengths(fibers);
  gpu::downloadFromBuffer(context, dataset.fiberLength(), lengths.data(), lengths.size() * sizeof(float));
  finiteRange(lengths, settings.scalar_min, settings.scalar_max);  // none finite: the default range stays
}

std::unique_ptr<gpu::VulkanContext> createRenderContext(const RenderCliOptions& o) {
  gpu::ContextOptions options;
  options.instance.validation = o.validate;
  options.device_name = o.device;
  return std::make_unique<gpu::VulkanContext>(options);
}

void checkValidation(const gpu::VulkanContext& context, const RenderCliOptions& o) {
  if (!o.validate) return;
  const int errors = context.log().errors(), warnings = context.log().warnings();
  if (errors + warnings > 0)
    throw Error("validation layers reported " + std::to_string(errors) + " errors and " + std::to_string(warnings) +
                " warnings (printed above)");
}

}  // namespace fibscope
