// Mouse and keys to viewer actions, as mrview users expect: left drag
// orbits, middle drag or shift + left drag pans, the wheel dollies; keys
// 1/2/3 (or S/C/A) the sagittal, coronal and axial views, R resets,
// F12 (or P) takes a screenshot; I/J/K choose the active anatomical slice,
// Page Up/Down move it a voxel (shift: ten); dropped files are opened
// (.nii/.nii.gz as the anatomical image, a .obj as a mesh cut that hides
// what lies outside it). A left click
// (press and release within kClickSlopPx) picks the fiber under it,
// ctrl + click adds it to (or removes it from) the selection. The
// dissection's ROIs: a right click places a sphere at the fiber under the
// cursor (on the focal plane over the background), a right drag moves the
// selected ROI in the view plane, shift + wheel or ] and [ resize it,
// Delete removes it. ImGui gets the mouse and keyboard first when it wants
// them (a drag that starts on a panel stays with the panel).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "app/viewer/viewer_actions.h"

namespace fibscope {

// What the window reports (viewer_window turns GLFW callbacks into these).
struct InputEvent {
  enum class Type : uint8_t { CursorMoved, MouseButton, Scroll, Key, Drop };
  enum Button : int { kLeft = 0, kRight = 1, kMiddle = 2 };
  Type type = Type::CursorMoved;
  double x = 0, y = 0;  // CursorMoved, MouseButton: framebuffer pixels (screenToFramebuffer); Scroll: wheel offsets
  int button = 0;       // MouseButton
  int key = 0;          // Key: a GLFW_KEY_* code
  bool pressed = false;  // MouseButton, Key (repeat counts as pressed)
  bool shift = false, control = false;
  std::vector<std::string> paths;  // Drop
};

// Whether a dropped file is a surface mesh (".obj", any case): a cut, not a model.
bool isObjPath(std::string_view path);

class InputMapper {
 public:
  // The actions `event` asks for. want_mouse / want_keyboard: ImGui's
  // io.WantCaptureMouse / io.WantCaptureKeyboard for this frame.
  std::vector<ViewerAction> map(const InputEvent& event, bool want_mouse, bool want_keyboard);

  // A left press and release farther apart than this (window pixels, either
  // axis) is a drag, not a click.
  static constexpr double kClickSlopPx = 3.0;

 private:
  enum class Drag : uint8_t { None, Orbit, Pan, MoveRoi };
  Drag drag_ = Drag::None;
  int drag_button_ = -1;
  bool have_cursor_ = false;
  double last_x_ = 0, last_y_ = 0;
  // The left press that may become a click: where, with ctrl, and whether
  // the cursor has left the slop since.
  bool click_armed_ = false, click_add_ = false;
  bool roi_click_armed_ = false;  // the right press that may become a click (a sphere placed)
  double press_x_ = 0, press_y_ = 0;
};

}  // namespace fibscope
