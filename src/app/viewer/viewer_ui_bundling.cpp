// The Bundle panel (viewer_ui.h): the bundling parameters (BundleParams,
// the paper's defaults), a Bundle button for the active model, the running
// job's progress with rate and ETA, the original / bundled / side-by-side toggle and
// "Save bundled...". Like the other panels it edits ViewerState and asks
// for the rest through actions (BundleAction, ShowOnlyModelAction, ...).
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "app/viewer/viewer_ui.h"
#include "core/progress.h"

namespace fibscope {
namespace {

void progressSection(const LoadingInfo& l) {
  const float fraction = l.total > 0 ? float(std::min(1.0, l.done / l.total)) : -1.0f;
  char overlay[160];
  if (fraction >= 0) std::snprintf(overlay, sizeof overlay, "%s %.0f%%", l.label.c_str(), 100.0 * fraction);
  else std::snprintf(overlay, sizeof overlay, "%s", l.label.empty() ? "starting" : l.label.c_str());
  ImGui::ProgressBar(fraction >= 0 ? fraction : float(std::fmod(l.elapsed_seconds, 1.0)), ImVec2(-1, 0), overlay);
  if (l.rate > 0) {
    const std::string unit = l.unit.empty() ? "" : " " + l.unit;
    std::string line = formatCount(l.done) + unit + "  " + formatCount(l.rate) + unit + "/s";
    if (l.eta_seconds >= 0) line += "  ETA " + formatDuration(l.eta_seconds);
    ImGui::TextDisabled("%s", line.c_str());
  }
}

}  // namespace

void drawBundlingPanel(ViewerState& state, std::vector<ViewerAction>& actions) {
  // At the right, under the performance overlay, sized to its content.
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(viewport->WorkPos.x + viewport->WorkSize.x - 330, viewport->WorkPos.y + 360),
                          ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Bundle", &state.show_bundling, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::End();
    return;
  }
  BundlingInfo& b = state.bundling;
  BundleParams& p = b.params;
  ImGui::BeginDisabled(b.running);
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("radius R (voxels)", &p.radius, 1, 5, "%.3g");
  int iterations = int(p.iterations);
  ImGui::SetNextItemWidth(120);
  if (ImGui::InputInt("iterations", &iterations)) p.iterations = uint32_t(std::clamp(iterations, 1, 1000));
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("radius decay", &p.radius_decay, 0.01, 0.05, "%.3g");
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("voxel (mm, 0: auto)", &p.voxel_mm, 0.1, 1, "%.3g");
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("step (mm, 0: auto)", &p.step_mm, 0.1, 1, "%.3g");
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("smoothing phi", &p.smoothing, 0.05, 0.1, "%.3g");
  ImGui::SetNextItemWidth(120);
  ImGui::InputDouble("relaxation alpha", &p.relaxation, 0.05, 0.1, "%.3g");
  int mode = p.mode == BundleMode::Anisotropic ? 1 : 0;
  ImGui::SetNextItemWidth(120);
  if (ImGui::Combo("mode", &mode, "isotropic\0anisotropic\0")) p.mode = mode ? BundleMode::Anisotropic : BundleMode::Isotropic;
  if (p.mode == BundleMode::Anisotropic) ImGui::InputDouble("anisotropy", &p.anisotropy, 0.05, 0.1, "%.3g");
  // Structure-aware advection (docs/BUNDLING.md): sheets stay sheets.
  ImGui::Checkbox("structure-aware", &p.structure_aware);
  if (p.structure_aware) {
    int power = int(p.structure_power);
    ImGui::SetNextItemWidth(120);
    if (ImGui::InputInt("structure power", &power)) p.structure_power = uint32_t(std::clamp(power, 1, 8));
    ImGui::SetNextItemWidth(120);
    ImGui::InputDouble("structure scale (R)", &p.structure_scale, 0.1, 0.5, "%.3g");
  }
  const bool has_model = state.active_model >= 0 && state.active_model < int(state.models.size());
  ImGui::BeginDisabled(!has_model);
  const std::string label =
      has_model ? "Bundle " + state.models[size_t(state.active_model)].name : std::string("Bundle (no model)");
  if (ImGui::Button(label.c_str())) actions.push_back(BundleAction{p});
  ImGui::EndDisabled();
  ImGui::EndDisabled();
  if (b.running) {
    progressSection(b.progress);
    if (ImGui::Button("Cancel")) actions.push_back(CancelBundleAction{});
  }
  const int n = int(state.models.size());
  if (b.bundled_model >= 0 && b.bundled_model < n) {
    ImGui::Separator();
    const bool original_ok = b.source_model >= 0 && b.source_model < n;
    const bool split = state.split.on && state.split.left == b.source_model && state.split.right == b.bundled_model;
    const int shown = split ? 2 : state.models[size_t(b.bundled_model)].visible ? 1 : 0;
    ImGui::BeginDisabled(!original_ok);
    if (ImGui::RadioButton("original", shown == 0) && original_ok) {
      actions.push_back(SplitViewAction{});
      actions.push_back(ShowOnlyModelAction{b.source_model});
    }
    ImGui::EndDisabled();
    ImGui::SameLine();
    if (ImGui::RadioButton("bundled", shown == 1)) {
      actions.push_back(SplitViewAction{});
      actions.push_back(ShowOnlyModelAction{b.bundled_model});
    }
    ImGui::SameLine();
    ImGui::BeginDisabled(!original_ok);
    if (ImGui::RadioButton("side by side", shown == 2) && original_ok)
      actions.push_back(SplitViewAction{true, b.source_model, b.bundled_model});
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("original left, bundled right, one camera (no picking, no ROI filter meanwhile)");
    ImGui::SetNextItemWidth(160);
    ImGui::InputText("##save", &b.save_path);
    ImGui::SameLine();
    if (ImGui::Button("Save bundled...")) actions.push_back(SaveModelAction{b.bundled_model, b.save_path});
  }
  if (!b.message.empty()) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + 300);
    ImGui::TextUnformatted(b.message.c_str());
    ImGui::PopTextWrapPos();
  }
  ImGui::End();
}

void drawSplitViewOverlay(const ViewerState& state) {
  const SplitViewInfo& split = state.split;
  const int n = int(state.models.size());
  if (!split.on || split.left < 0 || split.left >= n || split.right < 0 || split.right >= n) return;
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  ImDrawList* draw = ImGui::GetBackgroundDrawList();  // under the panels, over the frame
  // The halves split the whole window (the frame), not the work area.
  const float middle = viewport->Pos.x + float(int(viewport->Size.x) / 2);
  draw->AddLine(ImVec2(middle, viewport->Pos.y), ImVec2(middle, viewport->Pos.y + viewport->Size.y),
                IM_COL32(200, 200, 200, 160), 1.0f);
  const float top = viewport->WorkPos.y + 6;
  auto label = [&](int model, float x) {
    const std::string& name = state.models[size_t(model)].name;
    draw->AddText(ImVec2(x + 1, top + 1), IM_COL32(0, 0, 0, 200), name.c_str());
    draw->AddText(ImVec2(x, top), IM_COL32(255, 255, 255, 230), name.c_str());
  };
  label(split.left, viewport->Pos.x + 8);
  label(split.right, middle + 8);
}

}  // namespace fibscope
