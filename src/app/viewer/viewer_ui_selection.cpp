// The selection panel: what a click (ctrl-click) on the scene selected, the
// fibers' lengths, clearing, export to .tck and how the selection is shown.
// Appears while something is selected (the Window menu hides it).
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "app/viewer/viewer_ui.h"

namespace fibscope {

void drawSelectionPanel(ViewerState& state, std::vector<ViewerAction>& actions) {
  SelectionInfo& selection = state.selection;
  if (selection.fibers.empty()) return;
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  // Bottom right: the performance overlay holds the top right.
  ImGui::SetNextWindowPos(ImVec2(viewport->WorkPos.x + viewport->WorkSize.x - 10,
                                 viewport->WorkPos.y + viewport->WorkSize.y - 40),
                          ImGuiCond_FirstUseEver, ImVec2(1, 1));
  ImGui::SetNextWindowSize(ImVec2(260, 0), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Selection", &state.show_selection)) {
    ImGui::End();
    return;
  }
  const size_t n = selection.fibers.size();
  ImGui::Text("%zu fiber%s selected", n, n == 1 ? "" : "s");
  ImGui::SameLine();
  if (ImGui::SmallButton("Clear")) actions.push_back(ClearSelectionAction{});
  ImGui::TextDisabled("click: select, ctrl-click: add or remove");
  if (ImGui::Checkbox("show as tubes", &state.tubes.selection) && state.tubes.selection) state.show_tubes = true;

  // A scrolling table: at most ~8 rows tall, the clipper draws only the
  // visible rows of a long selection.
  const float row = ImGui::GetTextLineHeightWithSpacing();
  const float height = row * float(std::min<size_t>(n, 8) + 1) + 4;
  if (ImGui::BeginTable("fibers", 3,
                        ImGuiTableFlags_ScrollY | ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersOuter |
                            ImGuiTableFlags_SizingStretchSame,
                        ImVec2(0, height))) {
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("model");
    ImGui::TableSetupColumn("fiber");
    ImGui::TableSetupColumn("length");
    ImGui::TableHeadersRow();
    ImGuiListClipper clipper;
    clipper.Begin(int(n));
    while (clipper.Step()) {
      for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
        const SelectedFiber& f = selection.fibers[size_t(i)];
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(f.model.c_str());
        ImGui::TableNextColumn();
        ImGui::Text("%u", f.fiber);
        ImGui::TableNextColumn();
        if (f.length_mm) ImGui::Text("%.1f mm", double(*f.length_mm));
        else ImGui::TextDisabled("unknown");
      }
    }
    ImGui::EndTable();
  }

  ImGui::Separator();
  ImGui::SetNextItemWidth(-1);
  ImGui::InputTextWithHint("##export", "selection.tck", &selection.export_path);
  if (!selection.exportable) ImGui::BeginDisabled();
  if (ImGui::Button("Export .tck") && !selection.export_path.empty())
    actions.push_back(ExportSelectionAction{selection.export_path});
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("Writes the selected fibers of one model: the active model's, or the model of the fiber "
                      "selected last when the active one has none");
  if (!selection.exportable) {
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::TextDisabled("(the models' .fbl is not ready)");
  }

  ImGui::Separator();
  RenderSettings& s = state.settings;
  ImGui::ColorEdit3("highlight", s.highlight_color.data());
  ImGui::SliderFloat("dim others", &s.dim_unselected, 0.0f, 1.0f, "%.2f");
  ImGui::End();
}

}  // namespace fibscope
