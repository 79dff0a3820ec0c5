// The anatomy panel (viewer_ui.h): load an image by path (or drop one on
// the window), see its grid and values, and edit the anatomy entries of the
// settings table (group "anatomy") with the slice sliders spanning the
// loaded volume's voxels.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <filesystem>
#include <string>

#include "app/viewer/viewer_ui.h"
#include "render/settings_table.h"

namespace fibscope {

void drawAnatomyPanel(ViewerState& state, std::vector<ViewerAction>& actions) {
  ImGui::SetNextWindowPos(ImVec2(320, 30), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(320, 0), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Anatomy", &state.show_anatomy)) {
    ImGui::End();
    return;
  }
  ImGui::SetNextItemWidth(-60);
  const bool entered = ImGui::InputTextWithHint("##anatomy", "T1.nii.gz (or drop it on the window)", &state.anatomy_path,
                                                ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if ((ImGui::Button("Load") || entered) && !state.anatomy_path.empty())
    actions.push_back(AnatomyAction{state.anatomy_path});

  const AnatomyInfo& a = state.anatomy;
  if (!a.loaded()) {
    ImGui::TextDisabled("no image: NIfTI-1/2 scalar volumes (.nii, .nii.gz)");
    ImGui::End();
    return;
  }
  ImGui::Text("%s", std::filesystem::path(a.path).filename().string().c_str());
  ImGui::SameLine();
  if (ImGui::SmallButton("close")) actions.push_back(AnatomyAction{});
  ImGui::TextDisabled("%d x %d x %d voxels of %.3g x %.3g x %.3g mm, values %.4g to %.4g", a.dims[0], a.dims[1],
                      a.dims[2], a.voxel_mm[0], a.voxel_mm[1], a.voxel_mm[2], a.min, a.max);
  ImGui::TextDisabled("I/J/K: active slice, Page Up/Down: move it");

  RenderSettings& s = state.settings;
  for (const SettingInfo& info : renderSettingsTable()) {
    if (info.group != "anatomy") continue;
    if (info.name == "slice-i" || info.name == "slice-j" || info.name == "slice-k") {
      const int axis = info.name.back() - 'i';
      settingWidget(s, info, 0.0, a.dims[axis] > 1 ? double(a.dims[axis] - 1) : 1.0);
      continue;
    }
    settingWidget(s, info);
    if (info.name == "anatomy-range") {
      ImGui::SameLine();
      if (ImGui::SmallButton("robust")) {
        s.anatomy_min = a.robust_min;
        s.anatomy_max = a.robust_max;
      }
    }
  }
  ImGui::End();
}

}  // namespace fibscope
