#include "app/viewer/viewer_ui.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "render/settings_table.h"

namespace fibscope {

void settingWidget(RenderSettings& s, const SettingInfo& table_info, double min, double max) {
  SettingInfo info = table_info;
  if (min < max) {
    info.min = min;
    info.max = max;
  }
  const std::string label(info.label);
  const std::string unit = info.unit.empty() ? "" : " " + std::string(info.unit);
  // Wide ranges (LoD in px, the scalar range) read better on a log scale;
  // a range given here (a volume's voxels) is linear.
  const ImGuiSliderFlags flags =
      ImGuiSliderFlags_AlwaysClamp | (!(min < max) && info.max - info.min > 200 ? ImGuiSliderFlags_Logarithmic : 0);
  switch (info.kind) {
    case SettingKind::Flag: ImGui::Checkbox(label.c_str(), &(s.*info.flag)); break;
    case SettingKind::Integer:
      ImGui::SliderInt(label.c_str(), &(s.*info.integer), int(info.min), int(info.max), "%d", flags);
      break;
    case SettingKind::Number: {
      const std::string format = (info.max - info.min > 20 ? "%.1f" : "%.2f") + unit;
      ImGui::SliderFloat(label.c_str(), &(s.*info.number), float(info.min), float(info.max), format.c_str(), flags);
      break;
    }
    case SettingKind::Choice: {
      const int current = info.get_choice(s);
      const std::string name(info.choice_name(current));
      if (ImGui::BeginCombo(label.c_str(), name.c_str())) {
        for (int i = 0; i < info.choice_count; ++i) {
          const std::string option(info.choice_name(i));
          if (ImGui::Selectable(option.c_str(), i == current)) info.set_choice(s, i);
        }
        ImGui::EndCombo();
      }
      break;
    }
    case SettingKind::Color: ImGui::ColorEdit3(label.c_str(), (s.*info.color).data()); break;
    case SettingKind::Range: {
      float& lo = s.*info.number;
      float& hi = s.*info.number_max;
      ImGui::DragFloatRange2(label.c_str(), &lo, &hi, 0.5f, float(info.min), float(info.max), "%.1f", "%.1f",
                             ImGuiSliderFlags_AlwaysClamp);
      if (hi < lo) hi = lo;
      break;
    }
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", std::string(info.help).c_str());
}

namespace {

void settingsPanel(ViewerState& state, std::vector<ViewerAction>& actions) {
  ImGui::SetNextWindowPos(ImVec2(10, 200), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(300, 0), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Render settings", &state.show_settings)) {
    ImGui::End();
    return;
  }
  RenderSettings& s = state.settings;
  for (const SettingInfo& info : renderSettingsTable()) {
    if (info.relevant && !info.relevant(s)) continue;
    if (!info.group.empty()) continue;  // its own panel's
    if (info.name == "colormap") ImGui::TextDisabled("scalar: fiber length (mm)");
    settingWidget(s, info);
    if (info.name == "pipeline" && state.baseline_draws_active_only)
      ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s draws the active model only",
                         std::string(renderPipelineName(s.pipeline)).c_str());
    if (info.name == "scalar-range" && state.scalar_data_min <= state.scalar_data_max) {
      ImGui::SameLine();
      if (ImGui::SmallButton("fit")) {
        s.scalar_min = state.scalar_data_min;
        s.scalar_max = state.scalar_data_max;
      }
    }
  }
  ImGui::Checkbox("coarse while moving", &state.adaptive_detail);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("where a full frame takes over 100 ms: moves drawn with fiblets under the LoD size as one "
                      "segment; full detail when the camera stops");
  if (state.adaptive_detail) ImGui::SliderFloat("moving LoD", &state.moving_lod_px, 4.0f, 512.0f, "%.0f px");
  float fov = float(state.fov_deg);
  if (ImGui::SliderFloat("field of view", &fov, 10.0f, 90.0f, "%.0f deg")) actions.push_back(FovAction{fov});

  ImGui::Separator();
  ImGui::TextUnformatted("View");
  if (ImGui::Button("Sagittal")) actions.push_back(ViewAction{StandardView::Sagittal});
  ImGui::SameLine();
  if (ImGui::Button("Coronal")) actions.push_back(ViewAction{StandardView::Coronal});
  ImGui::SameLine();
  if (ImGui::Button("Axial")) actions.push_back(ViewAction{StandardView::Axial});
  ImGui::SameLine();
  if (ImGui::Button("Reset")) actions.push_back(ViewAction{});

  ImGui::Separator();
  ImGui::SetNextItemWidth(-1);
  ImGui::InputText("##shot", &state.screenshot_path);
  int size[2] = {state.screenshot_width, state.screenshot_height};
  if (ImGui::InputInt2("size (0: window)", size)) {
    state.screenshot_width = std::clamp(size[0], 0, 16384);
    state.screenshot_height = std::clamp(size[1], 0, 16384);
  }
  if (ImGui::Button("Screenshot")) {
    const bool sized = state.screenshot_width > 0 && state.screenshot_height > 0;
    actions.push_back(ScreenshotAction{state.screenshot_path, sized ? uint32_t(state.screenshot_width) : 0u,
                                       sized ? uint32_t(state.screenshot_height) : 0u});
  }
  ImGui::End();
}

void performanceOverlay(ViewerState& state) {
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(viewport->WorkPos.x + viewport->WorkSize.x - 10, viewport->WorkPos.y + 10),
                          ImGuiCond_Always, ImVec2(1, 0));
  ImGui::SetNextWindowBgAlpha(0.6f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove;
  if (!ImGui::Begin("Performance", &state.show_performance, flags)) {
    ImGui::End();
    return;
  }
  if (state.frames.empty()) {
    ImGui::TextUnformatted("no frame yet");
    ImGui::End();
    return;
  }
  // Averages over the last second or so smooth the numbers enough to read.
  const size_t n = std::min<size_t>(state.frames.size(), 30);
  double frame_ms = 0, gpu_ms = 0;
  for (size_t i = state.frames.size() - n; i < state.frames.size(); ++i) {
    frame_ms += state.frames[i].frame_ms;
    gpu_ms += state.frames[i].gpu.gpu_ms;
  }
  frame_ms /= double(n);
  gpu_ms /= double(n);
  ImGui::Text("frame %.1f ms (%.0f fps)", frame_ms, frame_ms > 0 ? 1000.0 / frame_ms : 0.0);
  ImGui::Text("GPU   %.1f ms", gpu_ms);
  if (state.coarse_frame) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "moving: coarse (LoD %.0f px)", state.moving_lod_px);
  float history[ViewerState::kFrameHistory];
  for (size_t i = 0; i < state.frames.size(); ++i) history[i] = float(state.frames[i].frame_ms);
  ImGui::PlotLines("##frames", history, int(state.frames.size()), 0, nullptr, 0.0f, FLT_MAX, ImVec2(220, 40));
  const FrameStats& last = state.frames.back().gpu;
  if (ImGui::BeginTable("passes", 2, ImGuiTableFlags_SizingFixedFit)) {
    for (const PassTiming& p : last.passes) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(p.name.c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%6.2f ms", p.ms);
    }
    ImGui::EndTable();
  }
  if (last.fiblets_total > 0)
    ImGui::Text("fiblets %llu + %llu LoD of %llu", static_cast<unsigned long long>(last.fiblets_drawn),
                static_cast<unsigned long long>(last.fiblets_lod),
                static_cast<unsigned long long>(last.fiblets_total));
  else
    ImGui::Text("segments %llu", static_cast<unsigned long long>(last.segments_total));
  ImGui::End();
}

void statusLine(const ViewerState& state) {
  if (state.status.empty()) return;
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(viewport->WorkPos.x + 10, viewport->WorkPos.y + viewport->WorkSize.y - 10),
                          ImGuiCond_Always, ImVec2(0, 1));
  ImGui::SetNextWindowBgAlpha(0.6f);
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoNav |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoMove);
  ImGui::TextUnformatted(state.status.c_str());
  ImGui::End();
}

}  // namespace

std::vector<ViewerAction> drawViewerUi(ViewerState& state) {
  std::vector<ViewerAction> actions;
  if (ImGui::BeginMainMenuBar()) {
    if (ImGui::BeginMenu("Window")) {
      ImGui::MenuItem("Models", nullptr, &state.show_models);
      ImGui::MenuItem("Render settings", nullptr, &state.show_settings);
      ImGui::MenuItem("Performance", nullptr, &state.show_performance);
      ImGui::MenuItem("Selection", nullptr, &state.show_selection);
      ImGui::MenuItem("Dissection", nullptr, &state.show_dissection);
      ImGui::MenuItem("Anatomy", nullptr, &state.show_anatomy);
      ImGui::MenuItem("Bundle", nullptr, &state.show_bundling);
      ImGui::MenuItem("Tubes", nullptr, &state.show_tubes);
      ImGui::EndMenu();
    }
    if (ImGui::MenuItem("Screenshot")) actions.push_back(ScreenshotAction{});
    ImGui::EndMainMenuBar();
  }
  if (state.show_models) drawModelsPanel(state, actions);
  drawLoadingOverlay(state);
  if (state.show_settings) settingsPanel(state, actions);
  if (state.show_performance) performanceOverlay(state);
  if (state.show_selection) drawSelectionPanel(state, actions);
  drawDissectionOverlay(state);
  drawSplitViewOverlay(state);
  if (state.show_dissection) drawDissectionPanel(state, actions);
  if (state.show_anatomy) drawAnatomyPanel(state, actions);
  if (state.show_bundling) drawBundlingPanel(state, actions);
  if (state.show_tubes) drawTubesPanel(state, actions);
  statusLine(state);
  return actions;
}

}  // namespace fibscope
