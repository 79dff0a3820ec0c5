// The viewer's panels, all in one place (STYLE.md rule 10): they edit
// ViewerState (settings, model visibility and choice, UI flags), read its
// statistics, and ask for everything else (camera views, screenshots,
// opening files) by returning actions for ViewerApp::apply. Call between
// ImGuiLayer::newFrame and record.
#pragma once

#include <vector>

#include <cmath>

#include "app/viewer/viewer_actions.h"
#include "app/viewer/viewer_state.h"
#include "render/settings_table.h"

namespace fibscope {

// The panel's widget of one setting of render/settings_table.h: its label,
// its range (sliders clamp to it; min < max replaces the table's, e.g. a
// slice's by the loaded volume), its help as the tooltip.
void settingWidget(RenderSettings& settings, const SettingInfo& info, double min = NAN, double max = NAN);

std::vector<ViewerAction> drawViewerUi(ViewerState& state);

// viewer_ui_models.cpp: the models panel (list, statistics, load progress,
// failed loads, open with recent files) and the small overlay shown while a
// load runs.
void drawModelsPanel(ViewerState& state, std::vector<ViewerAction>& actions);
void drawLoadingOverlay(const ViewerState& state);

// viewer_ui_selection.cpp: the selection panel (the selected fibers with
// index and length, clear, export to .tck, highlight colour and dimming),
// shown while something is selected.
void drawSelectionPanel(ViewerState& state, std::vector<ViewerAction>& actions);

// viewer_ui_dissection.cpp: the dissection panel (ROIs, length limits, the
// kept count, hide or dim, clip planes and slab, ROI set files, export of
// the kept fibers, the mouse bindings) and the ROIs' outlines over the
// scene (drawn whether the panel is open or not).
void drawDissectionPanel(ViewerState& state, std::vector<ViewerAction>& actions);
void drawDissectionOverlay(const ViewerState& state);
// viewer_ui_anatomy.cpp: the anatomy panel (the image's path entry, its
// grid and values, the slices with sliders over its voxels, the display
// range, opacity, sampling, the slab following the active slice).
void drawAnatomyPanel(ViewerState& state, std::vector<ViewerAction>& actions);
// viewer_ui_bundling.cpp: the Bundle panel (the bundling parameters, Bundle
// and Cancel, the job's progress with rate and ETA, original / bundled /
// side by side, Save bundled...).
void drawBundlingPanel(ViewerState& state, std::vector<ViewerAction>& actions);
// viewer_ui_bundling.cpp: over a split view, each half's model name and the
// line between the halves.
void drawSplitViewOverlay(const ViewerState& state);
// viewer_ui_tubes.cpp: the Tubes panel (selection / filtered fibers as
// spline tubes, radius, tolerance, method, rings, vertices, MSAA, the
// last build).
void drawTubesPanel(ViewerState& state, std::vector<ViewerAction>& actions);

}  // namespace fibscope
