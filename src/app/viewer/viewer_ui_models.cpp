// The models panel and the loading overlay (viewer_ui.h): the list of
// loaded models with their statistics, the running load's progress, the
// loads that failed, and the "Open" entry with the recent files. Like the
// other panels it edits ViewerState (visibility, the active model, dismissed
// failures) and asks for the rest (open, close) through actions.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "app/viewer/viewer_ui.h"
#include "core/progress.h"

namespace fibscope {
namespace {

std::string displayName(const std::string& path) {
  if (path.empty()) return "phantom";
  const std::string name = std::filesystem::path(path).filename().string();
  return name.empty() ? path : name;
}

// 0..1, or -1 when the total is unknown.
float progressFraction(const LoadingInfo& l) {
  return l.total > 0 ? float(std::min(1.0, l.done / l.total)) : -1.0f;
}

void loadingSection(const ViewerState& state) {
  const LoadingInfo& l = state.loading.front();
  ImGui::Text("Loading %s", displayName(l.path).c_str());
  const float fraction = progressFraction(l);
  char overlay[160];
  if (fraction >= 0) {
    std::snprintf(overlay, sizeof(overlay), "%s %.0f%%", l.label.c_str(), 100.0 * fraction);
  } else {
    std::snprintf(overlay, sizeof(overlay), "%s (%s)", l.label.empty() ? "starting" : l.label.c_str(),
                  formatDuration(l.elapsed_seconds).c_str());
  }
  // An unknown total shows as a bar that sweeps with the elapsed time.
  const float shown = fraction >= 0 ? fraction : float(std::fmod(l.elapsed_seconds, 1.0));
  ImGui::ProgressBar(shown, ImVec2(-1, 0), overlay);
  if (l.rate > 0) {
    const std::string unit = l.unit.empty() ? "" : " " + l.unit;
    std::string line = formatCount(l.done) + unit + "  " + formatCount(l.rate) + unit + "/s";
    if (l.eta_seconds >= 0) line += "  ETA " + formatDuration(l.eta_seconds);
    ImGui::TextDisabled("%s", line.c_str());
  }
  if (l.queued > 0) ImGui::TextDisabled("%zu more queued", l.queued);
}

void failuresSection(ViewerState& state) {
  const ImVec4 red(1.0f, 0.45f, 0.4f, 1.0f);
  for (size_t i = 0; i < state.load_failures.size();) {
    ImGui::PushID(int(i) + 100000);
    const bool dismiss = ImGui::SmallButton("x");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Dismiss");
    ImGui::SameLine();
    ImGui::PushStyleColor(ImGuiCol_Text, red);
    ImGui::TextWrapped("%s", state.load_failures[i].message.c_str());
    ImGui::PopStyleColor();
    ImGui::PopID();
    if (dismiss) state.load_failures.erase(state.load_failures.begin() + std::ptrdiff_t(i));
    else ++i;
  }
}

void statisticsTable(const ModelInfo& m) {
  if (!ImGui::BeginTable("stats", 2, ImGuiTableFlags_SizingFixedFit)) return;
  auto row = [](const char* name, const std::string& value) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextDisabled("%s", name);
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(value.c_str());
  };
  auto count = [](uint64_t n) { return formatCount(double(n)); };
  char text[128];
  row("streamlines", count(m.streamlines));
  row("points", count(m.points));
  row("segments", count(m.segments));
  row("fiblets", count(m.fiblets));
  std::snprintf(text, sizeof(text), "%.3g mm", m.step_mm);
  row("step", text);
  if (m.input_bytes > 0) row("input", formatBytes(double(m.input_bytes)));
  row(".fbl", formatBytes(double(m.fbl_bytes)));
  if (m.input_bytes > 0 && m.fbl_bytes > 0) {
    std::snprintf(text, sizeof(text), "%.1f : 1", double(m.input_bytes) / double(m.fbl_bytes));
    row("ratio", text);
  }
  if (m.from_cache) {
    row("source", m.path.size() > 4 && m.path.substr(m.path.size() - 4) == ".fbl" ? "opened as stored" : "from cache");
  } else {
    std::snprintf(text, sizeof(text), "compressed in %.2f s", m.compress_seconds);
    row("source", text);
    std::snprintf(text, sizeof(text), "mean %.1f um, max %.1f um", m.mean_error_um, m.max_error_um);
    row("codec error", text);
  }
  std::snprintf(text, sizeof(text), "%.2f s", m.load_seconds);
  row("load", text);
  ImGui::EndTable();
}

void modelList(ViewerState& state, std::vector<ViewerAction>& actions) {
  for (int i = 0; i < int(state.models.size()); ++i) {
    ModelInfo& m = state.models[size_t(i)];
    ImGui::PushID(i);
    ImGui::Checkbox("##visible", &m.visible);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Show or hide: every visible model is drawn");
    ImGui::SameLine();
    if (ImGui::SmallButton("x")) actions.push_back(CloseModelAction{i});
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Close this model");
    ImGui::SameLine();
    if (ImGui::Selectable(m.name.c_str(), state.active_model == i)) state.active_model = i;
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("%s\nClick to make it the active model: its statistics below, the scalar range's fit, "
                        "the export of selected fibers, and the model the baseline pipelines (lines, raw-compute) "
                        "draw alone.",
                        m.path.empty() ? "the built-in phantom" : m.path.c_str());
    ImGui::PopID();
  }
  if (state.models.empty()) ImGui::TextDisabled("no model");
  const int a = state.active_model;
  if (a >= 0 && a < int(state.models.size())) {
    ImGui::Separator();
    ImGui::PushID("active");
    statisticsTable(state.models[size_t(a)]);
    ImGui::PopID();
  }
}

void openSection(ViewerState& state, std::vector<ViewerAction>& actions) {
  ImGui::SetNextItemWidth(-60);
  const bool enter = ImGui::InputTextWithHint("##path", "file.tck / .trk(.gz) / .tt.gz / .trx / .vtk / .vtp / .fbl", &state.open_path,
                                              ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if ((ImGui::Button("Open") || enter) && !state.open_path.empty()) actions.push_back(OpenAction{state.open_path});
  if (state.recent_files.empty()) return;
  ImGui::SetNextItemWidth(-60);
  if (ImGui::BeginCombo("##recent", "recent files")) {
    for (const std::string& file : state.recent_files) {
      // Checked while the list is open only: a stat per entry.
      std::error_code ec;
      const bool exists = std::filesystem::exists(file, ec);
      ImGui::BeginDisabled(!exists);
      if (ImGui::Selectable(file.c_str(), false)) actions.push_back(OpenAction{file});
      ImGui::EndDisabled();
      if (!exists && ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("no longer exists");
    }
    ImGui::EndCombo();
  }
}

}  // namespace

void drawModelsPanel(ViewerState& state, std::vector<ViewerAction>& actions) {
  ImGui::SetNextWindowPos(ImVec2(10, 30), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(300, 0), ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Models", &state.show_models)) {
    ImGui::End();
    return;
  }
  if (!state.loading.empty()) {
    loadingSection(state);
    ImGui::Separator();
  }
  if (!state.load_failures.empty()) {
    failuresSection(state);
    ImGui::Separator();
  }
  modelList(state, actions);
  ImGui::Separator();
  openSection(state, actions);
  ImGui::End();
}

void drawLoadingOverlay(const ViewerState& state) {
  if (state.loading.empty()) return;
  const LoadingInfo& l = state.loading.front();
  const ImGuiViewport* viewport = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(viewport->WorkPos.x + viewport->WorkSize.x * 0.5f, viewport->WorkPos.y + 10),
                          ImGuiCond_Always, ImVec2(0.5f, 0));
  ImGui::SetNextWindowBgAlpha(0.6f);
  ImGui::Begin("##loading", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoNav |
                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoInputs);
  const float fraction = progressFraction(l);
  if (fraction >= 0)
    ImGui::Text("loading %s: %s %.0f%%", displayName(l.path).c_str(), l.label.c_str(), 100.0 * fraction);
  else
    ImGui::Text("loading %s: %s", displayName(l.path).c_str(), l.label.empty() ? "starting" : l.label.c_str());
  ImGui::End();
}

}  // namespace fibscope
