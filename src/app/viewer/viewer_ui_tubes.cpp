// The tubes panel (viewer_ui.h): which fibers are drawn as spline tubes
// over the lines (the selection's, the dissection's kept ones), their
// radius and resampling tolerance, the settings of group "tubes" (method,
// rings, vertices, MSAA) and the last build's numbers. The selection and
// dissection panels carry the same two switches.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <string>

#include "app/viewer/viewer_ui.h"
#include "render/settings_table.h"

namespace fibscope {

void drawTubesPanel(ViewerState& state, std::vector<ViewerAction>&) {
  ImGui::SetNextWindowPos(ImVec2(320, 300), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(320, 0), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Tubes", &state.show_tubes)) {
    ImGui::End();
    return;
  }
  TubesInfo& t = state.tubes;
  ImGui::Checkbox("show selection as tubes", &t.selection);
  ImGui::Checkbox("show filtered fibers as tubes", &t.filtered);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("The fibers the dissection's criteria keep");
  // Edited values rebuild the model once the edit ends (a drag would start
  // a build per step).
  float radius = t.radius_mm, tolerance = t.tolerance_mm;
  ImGui::SliderFloat("radius (mm)", &radius, 0.05f, 5.0f, "%.2f", ImGuiSliderFlags_Logarithmic);
  if (ImGui::IsItemDeactivatedAfterEdit() || (!ImGui::IsItemActive() && radius != t.radius_mm))
    t.radius_mm = std::max(radius, 0.01f);
  // The radius from a per-fiber array (committed on Enter or leaving the
  // field, as the sliders).
  std::string from = t.radius_from;
  ImGui::InputTextWithHint("radius from", "a per-fiber array (trk property, TRX dps)", &from);
  if (ImGui::IsItemDeactivatedAfterEdit()) t.radius_from = from;
  if (!t.radius_from.empty()) {
    float range[2] = {t.radius_min, t.radius_max};
    ImGui::DragFloat2("radius range (mm)", range, 0.01f, 0.01f, 10.0f, "%.2f");
    if (ImGui::IsItemDeactivatedAfterEdit() && range[0] > 0.0f && range[1] >= range[0])
      t.radius_min = range[0], t.radius_max = range[1];
  }
  ImGui::SliderFloat("tolerance (mm)", &tolerance, 0.0f, 0.5f, "%.3f");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Resampling: the tube's centre line stays within this distance of the fiber (0: every point)");
  if (ImGui::IsItemDeactivatedAfterEdit() || (!ImGui::IsItemActive() && tolerance != t.tolerance_mm))
    t.tolerance_mm = std::max(tolerance, 0.0f);
  for (const SettingInfo& info : renderSettingsTable())
    if (info.group == "tubes") settingWidget(state.settings, info);
  ImGui::Separator();
  if (t.building) {
    ImGui::TextDisabled("building the tubes...");
  } else if (!t.message.empty()) {
    ImGui::TextWrapped("%s", t.message.c_str());
  } else if (t.fibers > 0) {
    ImGui::Text("%llu tubes, %llu nodes of %llu points", static_cast<unsigned long long>(t.fibers),
                static_cast<unsigned long long>(t.nodes), static_cast<unsigned long long>(t.points));
    ImGui::TextDisabled("%llu segments, tubes buffer %.2f MiB, built in %.2f s",
                        static_cast<unsigned long long>(t.segments), double(t.bytes) / double(1 << 20),
                        t.build_seconds);
  } else {
    ImGui::TextDisabled(t.wanted() ? "no fibers to show" : "no tubes shown");
  }
  ImGui::End();
}

}  // namespace fibscope
