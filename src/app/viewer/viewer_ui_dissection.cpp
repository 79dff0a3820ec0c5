// The dissection panel (dissection.h): the ROIs with their roles, placed at
// the focal point and edited numerically; ends only and length limits; the
// models' per-fiber scalars, each with a range on or off; the
// kept count and how dropped fibers are shown; clip planes, the slab and
// mesh cuts (viewer_cuts.h);
// saving and loading the ROI set; exporting the kept fibers. And the ROIs'
// outlines over the scene, so that the mouse has something to aim at.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <string>
#include <tuple>

#include "app/viewer/viewer_ui.h"
#include "core/error.h"

namespace fibscope {
namespace {

const ImVec4 kWarning(1.0f, 0.8f, 0.3f, 1.0f);
const ImVec4 kError(1.0f, 0.45f, 0.4f, 1.0f);

const char* const kRoleNames[] = {"include", "exclude", "ordered"};

ImU32 roleColor(RoiRole role, bool enabled, bool selected) {
  if (!enabled) return selected ? IM_COL32(200, 200, 200, 255) : IM_COL32(130, 130, 130, 160);
  const int a = selected ? 255 : 190;
  switch (role) {
    case RoiRole::Include:
      return IM_COL32(90, 230, 120, a);
    case RoiRole::Exclude:
      return IM_COL32(240, 90, 80, a);
    case RoiRole::IncludeOrdered:
      return IM_COL32(80, 200, 240, a);
  }
  return IM_COL32(255, 255, 255, a);
}

glm::dvec3 focalPoint(const ViewerState& state) {
  return {state.camera.target[0], state.camera.target[1], state.camera.target[2]};
}

bool dragDouble3(const char* label, glm::dvec3& v, float speed, double min = -1e6, double max = 1e6) {
  return ImGui::DragScalarN(label, ImGuiDataType_Double, &v.x, 3, speed, &min, &max, "%.1f");
}

// The selected ROI's geometry, by kind; true when it changed.
bool regionEditor(Region& region) {
  if (auto* s = std::get_if<SphereRegion>(&region)) {
    bool changed = ImGui::DragFloat3("centre (mm)", s->center.data(), 0.25f, -1e6f, 1e6f, "%.1f");
    changed |= ImGui::DragFloat("radius (mm)", &s->radius, 0.1f, 0.1f, 1e4f, "%.1f", ImGuiSliderFlags_AlwaysClamp);
    return changed;
  }
  if (auto* b = std::get_if<BoxRegion>(&region)) {
    glm::dvec3 lo(b->min[0], b->min[1], b->min[2]), hi(b->max[0], b->max[1], b->max[2]);
    glm::dvec3 center = 0.5 * (lo + hi), size = hi - lo;
    bool changed = dragDouble3("centre (mm)", center, 0.25f);
    changed |= dragDouble3("size (mm)", size, 0.25f, 0.0, 1e5);
    if (changed)
      for (int k = 0; k < 3; ++k) {
        b->min[k] = center[k] - size[k] / 2;
        b->max[k] = center[k] + size[k] / 2;
      }
    return changed;
  }
  if (auto* o = std::get_if<OrientedBoxRegion>(&region)) {
    glm::dvec3 center(o->center[0], o->center[1], o->center[2]);
    glm::dvec3 size(2 * o->half[0], 2 * o->half[1], 2 * o->half[2]);
    glm::dvec3 angles(o->angles_deg[0], o->angles_deg[1], o->angles_deg[2]);
    bool changed = dragDouble3("centre (mm)", center, 0.25f);
    changed |= dragDouble3("size (mm)", size, 0.25f, 0.01, 1e5);
    changed |= dragDouble3("angles (deg)", angles, 0.5f, -360.0, 360.0);
    if (changed) {
      try {
        *o = orientedBox(center, size, angles);
      } catch (const Error&) {
        return false;  // a size dragged to 0: the box stays as it was
      }
    }
    return changed;
  }
  ImGui::TextDisabled("%s", regionSpec(region).c_str());  // a mask: its file, not edited here
  return false;
}

void roiList(ViewerState& state) {
  DissectionState& d = state.dissection;
  RoiSet& set = d.set;
  const double radius = defaultRoiRadius(state.scene_bounds);
  if (ImGui::Button("+ sphere")) {
    Roi roi{uniqueRoiName(set, "sphere"), sphereAt(focalPoint(state), radius), RoiRole::Include, true};
    set.rois.push_back(std::move(roi));
    d.selected = int(set.rois.size()) - 1;
  }
  ImGui::SameLine();
  if (ImGui::Button("+ box")) {
    set.rois.push_back(Roi{uniqueRoiName(set, "box"), boxAt(focalPoint(state), radius), RoiRole::Include, true});
    d.selected = int(set.rois.size()) - 1;
  }
  ImGui::SameLine();
  ImGui::TextDisabled("at the focal point");

  int remove = -1;
  if (!set.rois.empty() &&
      ImGui::BeginTable("rois", 4,
                        ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersOuter | ImGuiTableFlags_SizingFixedFit)) {
    ImGui::TableSetupColumn("on");
    ImGui::TableSetupColumn("name", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableSetupColumn("role");
    ImGui::TableSetupColumn("");
    ImGui::TableHeadersRow();
    for (size_t i = 0; i < set.rois.size(); ++i) {
      Roi& roi = set.rois[i];
      ImGui::PushID(int(i));
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Checkbox("##on", &roi.enabled);
      ImGui::TableNextColumn();
      ImGui::PushStyleColor(ImGuiCol_Text, ImGui::ColorConvertU32ToFloat4(roleColor(roi.role, true, false)));
      if (ImGui::Selectable(roi.name.empty() ? "(unnamed)" : roi.name.c_str(), d.selected == int(i)))
        d.selected = d.selected == int(i) ? -1 : int(i);
      ImGui::PopStyleColor();
      ImGui::TableNextColumn();
      int role = int(roi.role);
      ImGui::SetNextItemWidth(90);
      if (ImGui::Combo("##role", &role, kRoleNames, 3)) roi.role = RoiRole(role);
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("ordered: include regions entered in their list order");
      ImGui::TableNextColumn();
      if (ImGui::SmallButton("x")) remove = int(i);
      ImGui::PopID();
    }
    ImGui::EndTable();
  }
  if (remove >= 0) {
    set.rois.erase(set.rois.begin() + remove);
    if (d.selected == remove)
      d.selected = -1;
    else if (d.selected > remove)
      --d.selected;
  }
  if (d.selected >= 0 && d.selected < int(set.rois.size())) {
    Roi& roi = set.rois[size_t(d.selected)];
    ImGui::PushID("selected");
    ImGui::InputText("name", &roi.name);
    regionEditor(roi.region);
    ImGui::PopID();
  }
}

void lengthLimit(const char* label, double& value, double fallback) {
  bool on = !std::isnan(value);
  ImGui::PushID(label);
  if (ImGui::Checkbox(label, &on)) value = on ? fallback : NAN;
  if (on) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(-1);
    const double lo = 0, hi = 1e4;
    ImGui::DragScalar("##mm", ImGuiDataType_Double, &value, 0.5f, &lo, &hi, "%.1f mm", ImGuiSliderFlags_AlwaysClamp);
  }
  ImGui::PopID();
}

// The per-streamline arrays of the models drawn, a row per component:
// on/off, and when on, its [min, max] (started at the values' range); the
// set's ranges on arrays no model drawn has are listed after them (their
// fibers are all dropped: a missing value is NaN).
void scalarRanges(DissectionState& d) {
  RoiSet& set = d.set;
  const auto& arrays = d.stats.scalar_arrays;
  if (arrays.empty() && set.scalar_ranges.empty()) {
    ImGui::TextDisabled("the models carry no per-fiber scalars");
    return;
  }
  auto row = [&](const std::string& name, uint32_t k, float data_lo, float data_hi, bool present) {
    const std::string label = k == 0 ? name : name + "[" + std::to_string(k) + "]";
    ImGui::PushID(label.c_str());
    const int i = findScalarRange(set, name, k);
    bool on = i >= 0 && set.scalar_ranges[size_t(i)].enabled;
    const bool full = !on && enabledScalarRanges(set) >= FiberFilter::kMaxScalarRanges;
    ImGui::BeginDisabled(full);
    if (ImGui::Checkbox(label.c_str(), &on)) {
      if (i >= 0) {
        set.scalar_ranges[size_t(i)].enabled = on;
      } else {
        const bool known = data_lo <= data_hi;
        set.scalar_ranges.push_back(
            RoiScalarRange{ScalarRange{name, k, known ? double(data_lo) : NAN, known ? double(data_hi) : NAN}, true});
      }
    }
    ImGui::EndDisabled();
    if (!present) {
      ImGui::SameLine();
      ImGui::TextColored(kWarning, "(no model drawn has it)");
    } else if (data_lo <= data_hi) {
      ImGui::SameLine();
      ImGui::TextDisabled("%g .. %g", double(data_lo), double(data_hi));
    }
    const int j = findScalarRange(set, name, k);
    if (on && j >= 0) {
      ScalarRange& r = set.scalar_ranges[size_t(j)].range;
      // An open end shows as unchecked; checked, it starts at the data's bound.
      for (const auto& [what, bound, fallback] :
           {std::tuple{"min", &r.min, double(data_lo)}, std::tuple{"max", &r.max, double(data_hi)}}) {
        ImGui::PushID(what);
        bool limited = !std::isnan(*bound);
        ImGui::Indent();
        if (ImGui::Checkbox(what, &limited)) *bound = limited ? (std::isfinite(fallback) ? fallback : 0.0) : NAN;
        if (limited) {
          ImGui::SameLine();
          ImGui::SetNextItemWidth(-1);
          const float speed = data_lo < data_hi ? float(data_hi - data_lo) / 200.0f : 0.01f;
          ImGui::DragScalar("##v", ImGuiDataType_Double, bound, speed, nullptr, nullptr, "%.4g");
        }
        ImGui::Unindent();
        ImGui::PopID();
      }
      if (r.min > r.max) r.max = r.min;  // min <= max, as the filter requires
    }
    ImGui::PopID();
  };
  for (const auto& a : arrays)
    for (uint32_t k = 0; k < a.components; ++k) row(a.name, k, a.lo[k], a.hi[k], true);
  for (const RoiScalarRange& r : std::vector<RoiScalarRange>(set.scalar_ranges)) {
    const bool present = std::any_of(arrays.begin(), arrays.end(), [&](const auto& a) {
      return a.name == r.range.name && r.range.component < a.components;
    });
    if (!present) row(r.range.name, r.range.component, INFINITY, -INFINITY, false);
  }
}

// The mesh cuts: a spec typed (an OBJ path or a built-in shape) or a box or
// sphere at the focal point; each with its side, on/off and its closure
// note. Adding goes through an action (the mesh is read and uploaded
// first); the rest edits the set.
void cutMeshes(ViewerState& state, std::vector<ViewerAction>& actions) {
  DissectionState& d = state.dissection;
  RoiSet& set = d.set;
  const bool room = enabledCutMeshes(set) < kMaxCutMeshes;
  auto add = [&](const std::string& spec, bool cull_inside) {
    actions.push_back(DissectionAction{CutMeshAddEdit{MeshCut{spec, cull_inside}}});
  };
  if (!room) ImGui::BeginDisabled();
  const double size = defaultCutSize(state.scene_bounds);
  if (ImGui::Button("+ cut box")) add(regionSpec(boxAt(focalPoint(state), size)), true);
  ImGui::SameLine();
  if (ImGui::Button("+ cut sphere")) add(regionSpec(sphereAt(focalPoint(state), size)), true);
  ImGui::SameLine();
  ImGui::TextDisabled(room ? "at the focal point" : "at most 4 enabled");
  ImGui::SetNextItemWidth(-60);
  const bool entered = ImGui::InputTextWithHint("##cutspec", "cut.obj:outside | box:X0,Y0,Z0,X1,Y1,Z1:inside",
                                                &d.cut_mesh_spec, ImGuiInputTextFlags_EnterReturnsTrue);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("SPEC:inside|outside; SPEC an OBJ file or box:, obox:, sphere: as for regions");
  ImGui::SameLine();
  if ((ImGui::Button("Add") || entered) && !d.cut_mesh_spec.empty()) {
    try {
      const MeshCut cut = parseMeshCut(d.cut_mesh_spec);
      add(cut.spec, cut.cull_inside);
    } catch (const Error& e) {
      d.cut_mesh_message = e.what();
    }
  }
  if (!room) ImGui::EndDisabled();
  if (!d.cut_mesh_message.empty()) ImGui::TextWrapped("%s", d.cut_mesh_message.c_str());
  int remove = -1;
  for (size_t i = 0; i < set.cut_meshes.size(); ++i) {
    RoiCutMesh& m = set.cut_meshes[i];
    ImGui::PushID(int(i) + 1000);
    bool enabled = m.enabled;
    if (ImGui::Checkbox("##on", &enabled) && (!enabled || room)) m.enabled = enabled;
    ImGui::SameLine();
    int side = m.cut.cull_inside ? 0 : 1;
    ImGui::SetNextItemWidth(110);
    const char* const sides[] = {"hide inside", "hide outside"};
    if (ImGui::Combo("##side", &side, sides, 2)) m.cut.cull_inside = side == 0;
    ImGui::SameLine();
    if (ImGui::SmallButton("x")) remove = int(i);
    ImGui::SameLine();
    ImGui::TextUnformatted(m.cut.spec.c_str());
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", m.cut.spec.c_str());
    const auto note = d.cut_mesh_notes.find(m.cut.spec);
    if (note != d.cut_mesh_notes.end() && !note->second.empty()) ImGui::TextColored(kWarning, "%s", note->second.c_str());
    ImGui::PopID();
  }
  if (remove >= 0) set.cut_meshes.erase(set.cut_meshes.begin() + remove);
}

void cutsSection(ViewerState& state, std::vector<ViewerAction>& actions) {
  RoiSet& set = state.dissection.set;
  const bool room = enabledClipPlanes(set) < kMaxClipPlanes;
  if (!room) ImGui::BeginDisabled();
  if (ImGui::Button("+ clip plane")) set.clip_planes.push_back(RoiClipPlane{planeFacingViewer(state.camera), true});
  if (!room) ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::TextDisabled(room ? "at the focal point, facing you" : "at most 6 enabled");
  int remove = -1;
  for (size_t i = 0; i < set.clip_planes.size(); ++i) {
    RoiClipPlane& p = set.clip_planes[i];
    ImGui::PushID(int(i));
    bool enabled = p.enabled;
    if (ImGui::Checkbox("##on", &enabled) && (!enabled || room)) p.enabled = enabled;
    ImGui::SameLine();
    ImGui::Text("plane %zu", i + 1);
    ImGui::SameLine();
    if (ImGui::SmallButton("flip")) p.plane.normal = -p.plane.normal;
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("keep the other side");
    ImGui::SameLine();
    if (ImGui::SmallButton("x")) remove = int(i);
    ImGui::DragFloat3("point (mm)", &p.plane.point.x, 0.25f, -1e6f, 1e6f, "%.1f");
    glm::vec3 n = p.plane.normal;
    if (ImGui::DragFloat3("normal", &n.x, 0.01f, -1.0f, 1.0f, "%.2f") && glm::length(n) > 1e-4f)
      p.plane.normal = glm::normalize(n);  // kept unit; a zero normal is refused
    ImGui::PopID();
  }
  if (remove >= 0) set.clip_planes.erase(set.clip_planes.begin() + remove);

  RenderSettings& s = state.settings;
  ImGui::SliderFloat("slab", &s.slab_mm, 0.0f, 200.0f, s.slab_mm > 0 ? "%.1f mm" : "off", ImGuiSliderFlags_AlwaysClamp);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("draw only this thick a slab around the focal plane (moves with the view)");
  if (s.slab_mm > 0 && s.slab_follows_slice)
    ImGui::TextDisabled("the slab follows the active slice (%s)", std::string(sliceAxisName(s.active_slice)).c_str());
  cutMeshes(state, actions);
}

void filesSection(ViewerState& state, std::vector<ViewerAction>& actions) {
  DissectionState& d = state.dissection;
  ImGui::SetNextItemWidth(-120);
  ImGui::InputTextWithHint("##set", "dissection.json", &d.roi_set_path);
  ImGui::SameLine();
  if (ImGui::Button("Save") && !d.roi_set_path.empty()) actions.push_back(RoiSetFileAction{true, d.roi_set_path});
  ImGui::SameLine();
  if (ImGui::Button("Load") && !d.roi_set_path.empty()) actions.push_back(RoiSetFileAction{false, d.roi_set_path});
  if (!d.file_message.empty()) ImGui::TextWrapped("%s", d.file_message.c_str());

  ImGui::SetNextItemWidth(-120);
  ImGui::InputTextWithHint("##export", "kept.tck", &d.export_path);
  ImGui::SameLine();
  if (d.exporting) ImGui::BeginDisabled();
  if (ImGui::Button("Export kept") && !d.export_path.empty()) actions.push_back(ExportKeptAction{d.export_path});
  if (d.exporting) ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(
        "The active model's source file through the filter, as `fibscope filter IN OUT` with these "
        "criteria writes it (.tck, .trk, .trx; a .trx gets a group per ROI)");
  if (d.exporting) {
    ImGui::SameLine();
    ImGui::TextColored(kWarning, "exporting...");
  }
}

}  // namespace

void drawDissectionPanel(ViewerState& state, std::vector<ViewerAction>& actions) {
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  // The right column under the performance overlay, down to the bottom.
  const float top = std::min(360.0f, viewport->WorkSize.y * 0.45f);
  ImGui::SetNextWindowPos(ImVec2(viewport->WorkPos.x + viewport->WorkSize.x - 10, viewport->WorkPos.y + top),
                          ImGuiCond_FirstUseEver, ImVec2(1, 0));
  ImGui::SetNextWindowSize(ImVec2(340, std::max(120.0f, viewport->WorkSize.y - top - 10)), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Dissection", &state.show_dissection)) {
    ImGui::End();
    return;
  }
  DissectionState& d = state.dissection;
  const DissectionStats& stats = d.stats;
  if (!stats.error.empty()) {
    ImGui::TextColored(kError, "%s", stats.error.c_str());
  } else if (stats.active) {
    ImGui::Text("kept %llu of %llu fibers", static_cast<unsigned long long>(stats.kept),
                static_cast<unsigned long long>(stats.fibers));
    ImGui::SameLine();
    if (!stats.evaluated)
      ImGui::TextColored(kWarning, "updating...");
    else
      ImGui::TextDisabled("(%.0f ms)", stats.update_ms);
    if (ImGui::Checkbox("show kept as tubes", &state.tubes.filtered) && state.tubes.filtered) state.show_tubes = true;
  } else {
    ImGui::TextDisabled("no criteria: all %llu fibers kept", static_cast<unsigned long long>(stats.fibers));
  }
  int dim = d.dim_dropped ? 1 : 0;
  ImGui::TextUnformatted("dropped fibers:");
  ImGui::SameLine();
  ImGui::RadioButton("hide", &dim, 0);
  ImGui::SameLine();
  ImGui::RadioButton("dim", &dim, 1);
  d.dim_dropped = dim == 1;
  if (d.dim_dropped && !state.selection.fibers.empty())
    ImGui::TextDisabled("(the picked selection is not highlighted while dimming)");

  if (ImGui::CollapsingHeader("Regions", ImGuiTreeNodeFlags_DefaultOpen)) {
    roiList(state);
    ImGui::Checkbox("ends only", &d.set.ends_only);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("test only the first and last point of each fiber");
    lengthLimit("min length", d.set.min_length_mm, 20.0);
    lengthLimit("max length", d.set.max_length_mm, 250.0);
    if (!std::isnan(d.set.min_length_mm) && !std::isnan(d.set.max_length_mm) &&
        d.set.min_length_mm > d.set.max_length_mm)
      d.set.max_length_mm = d.set.min_length_mm;
  }
  if (ImGui::CollapsingHeader("Per-fiber scalars", ImGuiTreeNodeFlags_DefaultOpen)) scalarRanges(d);
  if (ImGui::CollapsingHeader("Cuts", ImGuiTreeNodeFlags_DefaultOpen)) cutsSection(state, actions);
  if (ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) filesSection(state, actions);
  if (ImGui::CollapsingHeader("Mouse")) {
    ImGui::TextWrapped(
        "right click: a sphere at the fiber under the cursor (on the focal plane over the background)\n"
        "right drag: move the selected ROI in the view plane\n"
        "shift + wheel, ] and [: resize the selected ROI\n"
        "Delete: remove the selected ROI\n"
        "(left drag orbits, middle or shift + left drag pans, click picks fibers)");
  }
  ImGui::End();
}

void drawDissectionOverlay(const ViewerState& state) {
  const DissectionState& d = state.dissection;
  if (d.set.rois.empty() || state.camera.width == 0 || state.camera.height == 0) return;
  const std::array<double, 16> m = viewProjectionD(state.camera);
  const ImVec2 scale = ImGui::GetIO().DisplayFramebufferScale;
  // World mm -> ImGui's coordinates (framebuffer pixels over the scale);
  // false behind the eye.
  auto project = [&](const glm::dvec3& p, ImVec2& out) {
    const double x = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
    const double y = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
    const double w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
    if (!(w > 1e-6)) return false;
    out = ImVec2(float((x / w + 1) * 0.5 * state.camera.width / std::max(scale.x, 1e-3f)),
                 float((y / w + 1) * 0.5 * state.camera.height / std::max(scale.y, 1e-3f)));
    return true;
  };
  const glm::dvec3 eye(state.camera.eye[0], state.camera.eye[1], state.camera.eye[2]);
  const glm::dvec3 forward =
      glm::normalize(glm::dvec3(state.camera.target[0], state.camera.target[1], state.camera.target[2]) - eye);
  const double px_per_mm_at_unit =
      state.camera.height / std::max(scale.y, 1e-3f) / (2 * std::tan(glm::radians(state.camera.fov_y_deg) / 2));
  ImDrawList* draw = ImGui::GetBackgroundDrawList();
  for (size_t i = 0; i < d.set.rois.size(); ++i) {
    const Roi& roi = d.set.rois[i];
    const bool selected = int(i) == d.selected;
    const ImU32 color = roleColor(roi.role, roi.enabled, selected);
    const float thickness = selected ? 2.5f : 1.5f;
    ImVec2 label_at;
    bool labelled = false;
    if (const auto* s = std::get_if<SphereRegion>(&roi.region)) {
      const glm::dvec3 c(s->center[0], s->center[1], s->center[2]);
      const double depth = glm::dot(c - eye, forward);
      ImVec2 at;
      if (depth <= 1e-3 || !project(c, at)) continue;
      const float r = float(double(s->radius) * px_per_mm_at_unit / depth);
      draw->AddCircle(at, r, color, 48, thickness);
      label_at = ImVec2(at.x + r * 0.72f, at.y - r * 0.72f);
      labelled = true;
    } else if (std::holds_alternative<BoxRegion>(roi.region) || std::holds_alternative<OrientedBoxRegion>(roi.region)) {
      // The 8 corners (bit k of the index: the +half side of axis k).
      glm::dvec3 center, axes[3];
      if (const auto* b = std::get_if<BoxRegion>(&roi.region)) {
        center = 0.5 * (glm::dvec3(b->min[0], b->min[1], b->min[2]) + glm::dvec3(b->max[0], b->max[1], b->max[2]));
        for (int k = 0; k < 3; ++k) {
          axes[k] = glm::dvec3(0);
          axes[k][k] = 0.5 * (b->max[k] - b->min[k]);
        }
      } else {
        const auto& o = std::get<OrientedBoxRegion>(roi.region);
        center = glm::dvec3(o.center[0], o.center[1], o.center[2]);
        for (int k = 0; k < 3; ++k) axes[k] = o.half[k] * glm::dvec3(o.axes[k][0], o.axes[k][1], o.axes[k][2]);
      }
      ImVec2 corner[8];
      bool visible = true;
      for (int c = 0; c < 8 && visible; ++c) {
        glm::dvec3 p = center;
        for (int k = 0; k < 3; ++k) p += ((c >> k) & 1 ? 1.0 : -1.0) * axes[k];
        visible = project(p, corner[c]);
      }
      if (!visible) continue;
      for (int c = 0; c < 8; ++c)
        for (int k = 0; k < 3; ++k)
          if (!((c >> k) & 1)) draw->AddLine(corner[c], corner[c | (1 << k)], color, thickness);
      label_at = corner[7];
      labelled = true;
    }
    if (labelled && !roi.name.empty()) draw->AddText(label_at, color, roi.name.c_str());
  }
}

}  // namespace fibscope
