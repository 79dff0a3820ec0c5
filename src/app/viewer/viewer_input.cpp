#include "app/viewer/viewer_input.h"

#include <GLFW/glfw3.h>

#include <cctype>
#include <cmath>
#include <string>

#include "app/viewer/viewer_anatomy.h"

namespace fibscope {

bool isObjPath(std::string_view path) {
  if (path.size() < 4) return false;
  std::string ext(path.substr(path.size() - 4));
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".obj";
}

std::vector<ViewerAction> InputMapper::map(const InputEvent& e, bool want_mouse, bool want_keyboard) {
  std::vector<ViewerAction> actions;
  switch (e.type) {
    case InputEvent::Type::CursorMoved: {
      const double dx = e.x - last_x_, dy = e.y - last_y_;
      if (click_armed_ && (std::abs(e.x - press_x_) > kClickSlopPx || std::abs(e.y - press_y_) > kClickSlopPx))
        click_armed_ = false;
      if (have_cursor_ && (dx != 0 || dy != 0)) {
        if (drag_ == Drag::Orbit) actions.push_back(OrbitAction{dx, dy});
        if (drag_ == Drag::Pan) actions.push_back(PanAction{dx, dy});
        if (drag_ == Drag::MoveRoi) {
          // Within the slop it may still be a click (a sphere placed): the
          // ROI moves once the cursor leaves it, by the whole way from the press.
          if (roi_click_armed_ &&
              (std::abs(e.x - press_x_) > kClickSlopPx || std::abs(e.y - press_y_) > kClickSlopPx)) {
            roi_click_armed_ = false;
            actions.push_back(RoiDragAction{e.x - press_x_, e.y - press_y_});
          } else if (!roi_click_armed_) {
            actions.push_back(RoiDragAction{dx, dy});
          }
        }
      }
      last_x_ = e.x;
      last_y_ = e.y;
      have_cursor_ = true;
      break;
    }
    case InputEvent::Type::MouseButton:
      if (!e.pressed) {
        if (e.button == InputEvent::kLeft && click_armed_) {
          actions.push_back(PickAction{press_x_, press_y_, click_add_});
          click_armed_ = false;
        }
        if (e.button == InputEvent::kRight && roi_click_armed_) {
          actions.push_back(RoiPlaceAction{press_x_, press_y_});
          roi_click_armed_ = false;
        }
        if (e.button == drag_button_) {
          drag_ = Drag::None;
          drag_button_ = -1;
        }
      } else if (!want_mouse && drag_ == Drag::None) {
        if (e.button == InputEvent::kLeft) {
          drag_ = e.shift ? Drag::Pan : Drag::Orbit;
          // The click picks at the press (the cursor may creep before the release).
          click_armed_ = !e.shift && have_cursor_;
          click_add_ = e.control;
          press_x_ = last_x_;
          press_y_ = last_y_;
        }
        if (e.button == InputEvent::kMiddle) drag_ = Drag::Pan;
        if (e.button == InputEvent::kRight && have_cursor_) {
          drag_ = Drag::MoveRoi;
          roi_click_armed_ = true;
          press_x_ = last_x_;
          press_y_ = last_y_;
        }
        if (drag_ != Drag::None) drag_button_ = e.button;
      }
      break;
    case InputEvent::Type::Scroll:
      if (!want_mouse && e.y != 0) {
        if (e.shift) actions.push_back(RoiResizeAction{e.y});
        else actions.push_back(DollyAction{e.y});
      }
      break;
    case InputEvent::Type::Key:
      if (!e.pressed || want_keyboard) break;
      switch (e.key) {
        case GLFW_KEY_1:
        case GLFW_KEY_S:
          actions.push_back(ViewAction{StandardView::Sagittal});
          break;
        case GLFW_KEY_2:
        case GLFW_KEY_C:
          actions.push_back(ViewAction{StandardView::Coronal});
          break;
        case GLFW_KEY_3:
        case GLFW_KEY_A:
          actions.push_back(ViewAction{StandardView::Axial});
          break;
        case GLFW_KEY_R:
          actions.push_back(ViewAction{});
          break;
        case GLFW_KEY_DELETE:
          actions.push_back(DissectionAction{RoiRemoveEdit{}});  // the selected ROI
          break;
        case GLFW_KEY_RIGHT_BRACKET:
          actions.push_back(RoiResizeAction{1});
          break;
        case GLFW_KEY_LEFT_BRACKET:
          actions.push_back(RoiResizeAction{-1});
          break;
        case GLFW_KEY_F12:
        case GLFW_KEY_P:
          actions.push_back(ScreenshotAction{});  // empty path: the viewer picks a fresh name
          break;
        // Anatomical slices (1/2/3 are the views): I/J/K choose the active
        // slice, Page Up/Down move it a voxel (ten with shift).
        case GLFW_KEY_I:
        case GLFW_KEY_J:
        case GLFW_KEY_K:
          actions.push_back(SetAction{"active-slice", std::string(1, char('i' + (e.key - GLFW_KEY_I)))});
          break;
        case GLFW_KEY_PAGE_UP:
        case GLFW_KEY_PAGE_DOWN:
          actions.push_back(SliceStepAction{(e.key == GLFW_KEY_PAGE_UP ? 1.0 : -1.0) * (e.shift ? 10.0 : 1.0)});
          break;
        default:
          break;
      }
      break;
    case InputEvent::Type::Drop:
      // A surface mesh becomes a cut keeping what lies inside it (the
      // fibers through a structure, the question a dropped mesh usually
      // asks; one click flips it); images go to the anatomy; anything else
      // opens as a model.
      for (const std::string& path : e.paths) {
        if (isObjPath(path))
          actions.push_back(DissectionAction{CutMeshAddEdit{MeshCut{path, /*cull_inside=*/false}}});
        else if (isNiftiPath(path))
          actions.push_back(AnatomyAction{path});
        else
          actions.push_back(OpenAction{path});
      }
      break;
  }
  return actions;
}

}  // namespace fibscope
