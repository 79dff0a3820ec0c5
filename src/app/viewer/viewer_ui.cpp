#include "app/viewer/viewer_ui.h"

#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace fibscope {
namespace {

// A combo over an enum whose values are 0..count-1 with names from `name`.
template <typename Enum, typename NameFn>
bool enumCombo(const char* label, Enum& value, int count, NameFn name) {
  bool changed = false;
  const std::string current(name(value));
  if (ImGui::BeginCombo(label, current.c_str())) {
    for (int i = 0; i < count; ++i) {
      const Enum option = Enum(i);
      const std::string text(name(option));
      if (ImGui::Selectable(text.c_str(), option == value)) {
        changed = option != value;
        value = option;
      }
    }
    ImGui::EndCombo();
  }
  return changed;
}

void settingsPanel(ViewerState& state, std::vector<ViewerAction>& actions) {
  ImGui::SetNextWindowPos(ImVec2(10, 200), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(300, 0), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Render settings", &state.show_settings)) {
    ImGui::End();
    return;
  }
  RenderSettings& s = state.settings;
  enumCombo("pipeline", s.pipeline, 3, renderPipelineName);
  if (state.baseline_draws_active_only)
    ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s draws the active model only",
                       std::string(renderPipelineName(s.pipeline)).c_str());
  if (s.pipeline == RenderPipeline::Compute) enumCombo("culling", s.culling, 3, cullingModeName);
  if (s.pipeline == RenderPipeline::Compute && s.culling != CullingMode::None)
    ImGui::SliderFloat("LoD below", &s.lod_pixels, 0.0f, 16.0f, "%.1f px");
  ImGui::SliderFloat("line width", &s.line_width_px, 1.0f, 4.0f, "%.1f px");
  enumCombo("colour", s.color, 5, colorModeName);
  if (s.color == ColorMode::Solid) ImGui::ColorEdit3("solid colour", s.solid_color.data());
  if (s.color == ColorMode::Scalar) {
    ImGui::TextDisabled("scalar: fiber length (mm)");
    enumCombo("colormap", s.colormap, 4, colormapName);
    ImGui::DragFloatRange2("range", &s.scalar_min, &s.scalar_max, 0.5f, 0.0f, 0.0f, "%.1f", "%.1f");
    if (s.scalar_max < s.scalar_min) s.scalar_max = s.scalar_min;
    if (state.scalar_data_min <= state.scalar_data_max) {
      ImGui::SameLine();
      if (ImGui::SmallButton("fit")) {
        s.scalar_min = state.scalar_data_min;
        s.scalar_max = state.scalar_data_max;
      }
    }
  }
  enumCombo("lighting", s.lighting, 2, lightingName);
  if (s.lighting == Lighting::IlluminatedLines && ImGui::TreeNode("light")) {
    ImGui::SliderFloat("ambient", &s.light_ambient, 0.0f, 1.0f, "%.2f");
    ImGui::SliderFloat("diffuse", &s.light_diffuse, 0.0f, 1.0f, "%.2f");
    ImGui::SliderFloat("specular", &s.light_specular, 0.0f, 1.0f, "%.2f");
    ImGui::SliderFloat("shininess", &s.light_shininess, 1.0f, 128.0f, "%.0f");
    ImGui::TreePop();
  }
  ImGui::Checkbox("ambient occlusion", &s.ssao);
  if (s.ssao) {
    ImGui::SliderFloat("AO radius", &s.ssao_radius_px, 1.0f, 40.0f, "%.0f px");
    ImGui::SliderFloat("AO strength", &s.ssao_strength, 0.0f, 1.0f, "%.2f");
    ImGui::SliderInt("AO scales", &s.ao_scales, 1, 4);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("multi-scale AO: radii r, 2r, 4r, 8r combined");
    ImGui::SliderFloat("AO range", &s.ssao_range_mm, 1.0f, 40.0f, "%.0f mm");
  }
  ImGui::Checkbox("FXAA", &s.fxaa);
  ImGui::Checkbox("coarse while moving", &state.adaptive_detail);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("where a full frame takes over 100 ms: moves drawn with fiblets under the LoD size as one "
                      "segment; full detail when the camera stops");
  if (state.adaptive_detail) ImGui::SliderFloat("moving LoD", &state.moving_lod_px, 4.0f, 512.0f, "%.0f px");
  ImGui::ColorEdit3("background", s.background.data());
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
  statusLine(state);
  return actions;
}

}  // namespace fibscope
