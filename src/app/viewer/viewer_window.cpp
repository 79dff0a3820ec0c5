#include "app/viewer/viewer_window.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <cstdlib>

namespace fibscope {
namespace {

std::string g_glfw_error;  // the last GLFW error (GLFW reports through a C callback)

void onGlfwError(int, const char* description) { g_glfw_error = description ? description : "unknown GLFW error"; }

}  // namespace

std::unique_ptr<ViewerWindow> ViewerWindow::open(uint32_t width, uint32_t height, const std::string& title,
                                                 std::string& why_not) {
  glfwSetErrorCallback(onGlfwError);
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!display || !*display) && (!wayland || !*wayland)) {
    why_not = "no display (DISPLAY is not set)";
    return nullptr;
  }
  if (!glfwInit()) {
    why_not = "GLFW cannot start: " + g_glfw_error;
    return nullptr;
  }
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    why_not = "GLFW finds no Vulkan loader for windows";
    return nullptr;
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  std::unique_ptr<ViewerWindow> w(new ViewerWindow);
  w->window_ = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
  if (!w->window_) {
    glfwTerminate();
    why_not = "GLFW cannot create a window: " + g_glfw_error;
    return nullptr;
  }
  glfwSetWindowUserPointer(w->window_, w.get());
  // Installed before ImGui's GLFW backend, which chains to them.
  glfwSetCursorPosCallback(w->window_, onCursor);
  glfwSetMouseButtonCallback(w->window_, onButton);
  glfwSetScrollCallback(w->window_, onScroll);
  glfwSetKeyCallback(w->window_, onKey);
  glfwSetDropCallback(w->window_, onDrop);
  return w;
}

ViewerWindow::~ViewerWindow() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

std::vector<std::string> ViewerWindow::requiredInstanceExtensions() {
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  std::vector<std::string> result;
  for (uint32_t i = 0; names && i < count; ++i) result.emplace_back(names[i]);
  return result;
}

VkSurfaceKHR ViewerWindow::createSurface(VkInstance instance) const {
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  if (glfwCreateWindowSurface(instance, window_, nullptr, &surface) != VK_SUCCESS) return VK_NULL_HANDLE;
  return surface;
}

void ViewerWindow::pollEvents() { glfwPollEvents(); }
void ViewerWindow::waitEvents() { glfwWaitEventsTimeout(0.1); }
bool ViewerWindow::shouldClose() const { return glfwWindowShouldClose(window_); }

void ViewerWindow::setSize(uint32_t width, uint32_t height) { glfwSetWindowSize(window_, int(width), int(height)); }

void ViewerWindow::framebufferSize(uint32_t& width, uint32_t& height) const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  width = uint32_t(w > 0 ? w : 0);
  height = uint32_t(h > 0 ? h : 0);
}

std::vector<InputEvent> ViewerWindow::takeEvents() {
  std::vector<InputEvent> events;
  events.swap(events_);
  return events;
}

void screenToFramebuffer(double& x, double& y, int window_width, int window_height, int framebuffer_width,
                         int framebuffer_height) {
  if (window_width <= 0 || window_height <= 0 || framebuffer_width <= 0 || framebuffer_height <= 0) return;
  x *= double(framebuffer_width) / double(window_width);
  y *= double(framebuffer_height) / double(window_height);
}

namespace {

// Events carry framebuffer pixels: picks and pans (the point under the
// cursor follows it) are then exact on any display scale.
void toFramebuffer(GLFWwindow* window, double& x, double& y) {
  int ww = 0, wh = 0, fw = 0, fh = 0;
  glfwGetWindowSize(window, &ww, &wh);
  glfwGetFramebufferSize(window, &fw, &fh);
  screenToFramebuffer(x, y, ww, wh, fw, fh);
}

}  // namespace

ViewerWindow& ViewerWindow::from(GLFWwindow* window) {
  return *static_cast<ViewerWindow*>(glfwGetWindowUserPointer(window));
}

void ViewerWindow::onCursor(GLFWwindow* window, double x, double y) {
  InputEvent e;
  e.type = InputEvent::Type::CursorMoved;
  e.x = x;
  e.y = y;
  toFramebuffer(window, e.x, e.y);
  from(window).events_.push_back(std::move(e));
}

void ViewerWindow::onButton(GLFWwindow* window, int button, int action, int mods) {
  InputEvent e;
  e.type = InputEvent::Type::MouseButton;
  e.button = button == GLFW_MOUSE_BUTTON_LEFT     ? InputEvent::kLeft
             : button == GLFW_MOUSE_BUTTON_MIDDLE ? InputEvent::kMiddle
             : button == GLFW_MOUSE_BUTTON_RIGHT  ? InputEvent::kRight
                                                  : button;
  e.pressed = action == GLFW_PRESS;
  e.shift = mods & GLFW_MOD_SHIFT;
  e.control = mods & GLFW_MOD_CONTROL;
  // The press position: the drag starts where the button went down.
  glfwGetCursorPos(window, &e.x, &e.y);
  toFramebuffer(window, e.x, e.y);
  from(window).events_.push_back(std::move(e));
}

void ViewerWindow::onScroll(GLFWwindow* window, double dx, double dy) {
  InputEvent e;
  e.type = InputEvent::Type::Scroll;
  e.x = dx;
  e.y = dy;
  // GLFW gives the wheel no modifiers: shift + wheel resizes a ROI.
  e.shift =
      glfwGetKey(window, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS || glfwGetKey(window, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
  from(window).events_.push_back(std::move(e));
}

void ViewerWindow::onKey(GLFWwindow* window, int key, int, int action, int mods) {
  InputEvent e;
  e.type = InputEvent::Type::Key;
  e.key = key;
  e.pressed = action == GLFW_PRESS;  // no auto-repeat: one key press, one view or screenshot
  e.shift = mods & GLFW_MOD_SHIFT;
  e.control = mods & GLFW_MOD_CONTROL;
  from(window).events_.push_back(std::move(e));
}

void ViewerWindow::onDrop(GLFWwindow* window, int count, const char** paths) {
  InputEvent e;
  e.type = InputEvent::Type::Drop;
  for (int i = 0; i < count; ++i) e.paths.emplace_back(paths[i]);
  from(window).events_.push_back(std::move(e));
}

}  // namespace fibscope
