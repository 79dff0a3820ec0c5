// The tubes panel (viewer_ui.h): which fibers are drawn as tubes over the
// lines (the selection's, the dissection's kept ones, every fiber), drawn
// as spline tubes or SVO streamtubes (straight or curved, the octree's
// voxel), their radius and resampling tolerance, the settings of group
// "tubes" (method, rings, vertices, MSAA), the running build's progress
// (tube model, voxelising, sorting, building, distance field) and the last
// build's numbers. The selection and dissection panels carry the same two
// switches.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "app/viewer/viewer_ui.h"
#include "core/progress.h"
#include "render/settings_table.h"

namespace fibscope {
namespace {

void buildProgress(const TubesInfo& t) {
  if (!t.progress) {
    ImGui::TextDisabled("building the tubes...");
    return;
  }
  const ProgressSnapshot& p = *t.progress;
  const float fraction = p.total > 0 ? float(std::min(1.0, p.done / p.total)) : -1.0f;
  char overlay[160];
  if (fraction >= 0) std::snprintf(overlay, sizeof overlay, "%s %.0f%%", p.label.c_str(), 100.0 * fraction);
  else std::snprintf(overlay, sizeof overlay, "%s", p.label.c_str());
  // An unknown total sweeps with the elapsed time.
  ImGui::ProgressBar(fraction >= 0 ? fraction : float(std::fmod(p.elapsed_seconds, 1.0)), ImVec2(-1, 0), overlay);
  if (p.rate > 0) {
    const std::string unit = p.unit.empty() ? "" : " " + p.unit;
    std::string line = formatCount(p.done) + unit + "  " + formatCount(p.rate) + unit + "/s";
    if (p.eta_seconds >= 0) line += "  ETA " + formatDuration(p.eta_seconds);
    ImGui::TextDisabled("%s", line.c_str());
  }
}

}  // namespace

void drawTubesPanel(ViewerState& state, std::vector<ViewerAction>&) {
  ImGui::SetNextWindowPos(ImVec2(320, 300), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(320, 0), ImGuiCond_FirstUseEver);
  // Auto-sized as the Bundle panel: the build's progress and numbers grow it.
  if (!ImGui::Begin("Tubes", &state.show_tubes, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::End();
    return;
  }
  TubesInfo& t = state.tubes;
  ImGui::Checkbox("show selection as tubes", &t.selection);
  ImGui::Checkbox("show filtered fibers as tubes", &t.filtered);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("The fibers the dissection's criteria keep");
  ImGui::Checkbox("show all fibers as tubes", &t.all);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Every fiber of the visible models");
  static const char* kDrawnAs[] = {"spline tubes", "SVO straight (svo-straight)", "SVO curved (svo-curved)"};
  int drawn_as = int(t.svo);
  if (ImGui::Combo("drawn as", &drawn_as, kDrawnAs, IM_ARRAYSIZE(kDrawnAs))) t.svo = TubesInfo::Svo(drawn_as);
  if (t.svo != TubesInfo::Svo::None) {
    float voxel = t.voxel_mm;
    ImGui::SliderFloat("voxel (mm)", &voxel, 0.0f, 2.0f, voxel > 0.0f ? "%.3f" : "from the data");
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("The octree's voxel; 0: half the smallest radius, within the step (chooseSvoGrid)");
    if (ImGui::IsItemDeactivatedAfterEdit() || (!ImGui::IsItemActive() && voxel != t.voxel_mm))
      t.voxel_mm = std::max(voxel, 0.0f);
    // Live: the trace reads it at every frame.
    ImGui::SliderFloat("level of detail", &t.svo_lod_px, 0.0f, 8.0f, t.svo_lod_px > 0.0f ? "%.1f px" : "off");
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("A node of the octree smaller than this many pixels stops the ray (its most referenced "
                        "segment stands in); 0: the exact walk");
  }
  // Edited values rebuild the model once the edit ends (a drag would start
  // a build per step).
  float radius = t.radius_mm, tolerance = t.tolerance_mm;
  ImGui::SliderFloat("radius (mm)", &radius, 0.05f, 5.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
  if (ImGui::IsItemDeactivatedAfterEdit() || (!ImGui::IsItemActive() && radius != t.radius_mm))
    t.radius_mm = std::max(radius, 0.01f);
  // The radius from a per-fiber or per-point array (committed on Enter or
  // leaving the field, as the sliders).
  std::string from = t.radius_from;
  ImGui::InputTextWithHint("radius from", "an array: trk property or scalar, TRX dps or dpv", &from);
  if (ImGui::IsItemDeactivatedAfterEdit()) t.radius_from = from;
  if (!t.radius_from.empty()) {
    float range[2] = {t.radius_min, t.radius_max};
    ImGui::DragFloat2("radius range (mm)", range, 0.01f, 0.01f, 10.0f, "%.2f");
    if (ImGui::IsItemDeactivatedAfterEdit() && range[0] > 0.0f && range[1] >= range[0])
      t.radius_min = range[0], t.radius_max = range[1];
  }
  if (t.svo == TubesInfo::Svo::None) {  // the octree keeps every point
    ImGui::SliderFloat("tolerance (mm)", &tolerance, 0.0f, 0.5f, "%.3f");
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("Resampling: the tube's centre line stays within this distance of the fiber (0: every point)");
    if (ImGui::IsItemDeactivatedAfterEdit() || (!ImGui::IsItemActive() && tolerance != t.tolerance_mm))
      t.tolerance_mm = std::max(tolerance, 0.0f);
  }
  // The spline tubes' settings: the octree's tubes use none of them.
  if (t.svo == TubesInfo::Svo::None)
    for (const SettingInfo& info : renderSettingsTable())
      if (info.group == "tubes") settingWidget(state.settings, info);
  ImGui::Separator();
  if (t.building) {
    buildProgress(t);
  } else if (!t.message.empty()) {
    ImGui::TextWrapped("%s", t.message.c_str());
  } else if (t.fibers > 0) {
    ImGui::Text("%llu tubes, %llu nodes of %llu points", static_cast<unsigned long long>(t.fibers),
                static_cast<unsigned long long>(t.nodes), static_cast<unsigned long long>(t.points));
    ImGui::TextDisabled("%llu segments, tubes buffer %.2f MiB, built in %.2f s",
                        static_cast<unsigned long long>(t.segments), double(t.bytes) / double(1 << 20),
                        t.build_seconds);
    if (t.svo_leaves > 0) {
      ImGui::Text("octree: %llu leaves, voxel %.3f mm, %u^3 grid", static_cast<unsigned long long>(t.svo_leaves),
                  double(t.svo_voxel), t.svo_side);
      ImGui::TextDisabled("nodes %.2f MiB, decoration %.2f MiB, %s in %.2f s", double(t.svo_nodes_bytes) / double(1 << 20),
                          double(t.svo_decoration_bytes) / double(1 << 20),
                          t.svo_from_cache ? "read from the cache" : "built", t.svo_seconds);
    }
    if (t.df_bytes > 0)
      ImGui::TextDisabled("distance field: voxel %.3f mm, %.1f MiB, built in %.2f s", double(t.df_voxel),
                          double(t.df_bytes) / double(1 << 20), t.df_seconds);
  } else {
    ImGui::TextDisabled(t.wanted() ? "no fibers to show" : "no tubes shown");
  }
  ImGui::End();
}

}  // namespace fibscope
