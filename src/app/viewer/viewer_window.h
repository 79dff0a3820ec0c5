// The viewer's GLFW window: no client API (Vulkan draws), resizable; its
// callbacks queue InputEvents for the frame loop (viewer_input maps them to
// actions) and note framebuffer resizes. GLFW is initialised by the first
// window and terminated with it.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/viewer/viewer_input.h"

struct GLFWwindow;

namespace fibscope {

// A cursor position in screen coordinates (GLFW's, what the mouse moves
// in) as framebuffer pixels (what the renderer draws and picks in): they
// differ on high-DPI displays, where a screen coordinate spans several
// pixels. Unscaled while either size is zero (a minimised window).
void screenToFramebuffer(double& x, double& y, int window_width, int window_height, int framebuffer_width,
                         int framebuffer_height);

class ViewerWindow {
 public:
  // A window of width x height screen coordinates, or null with `why_not`
  // set (one line) when there is no display, GLFW cannot start, or GLFW
  // finds no Vulkan loader: the viewer then runs offscreen.
  static std::unique_ptr<ViewerWindow> open(uint32_t width, uint32_t height, const std::string& title,
                                            std::string& why_not);
  ~ViewerWindow();
  ViewerWindow(const ViewerWindow&) = delete;
  ViewerWindow& operator=(const ViewerWindow&) = delete;

  GLFWwindow* handle() const { return window_; }
  // The instance extensions a surface for this window needs.
  static std::vector<std::string> requiredInstanceExtensions();
  // The window's surface (VK_NULL_HANDLE on failure), for ContextOptions::surface_factory.
  VkSurfaceKHR createSurface(VkInstance instance) const;

  // Processes pending window-system events (the callbacks run inside).
  void pollEvents();
  // Blocks until an event comes (a minimised window draws nothing).
  void waitEvents();
  bool shouldClose() const;
  // Asks for a window of width x height screen coordinates (the framebuffer
  // follows once the window system has applied it).
  void setSize(uint32_t width, uint32_t height);
  // The framebuffer's size in pixels (0 x 0 while minimised).
  void framebufferSize(uint32_t& width, uint32_t& height) const;
  // The events queued since the last call, in order.
  std::vector<InputEvent> takeEvents();

 private:
  ViewerWindow() = default;
  static ViewerWindow& from(GLFWwindow* window);
  static void onCursor(GLFWwindow* window, double x, double y);
  static void onButton(GLFWwindow* window, int button, int action, int mods);
  static void onScroll(GLFWwindow* window, double dx, double dy);
  static void onKey(GLFWwindow* window, int key, int scancode, int action, int mods);
  static void onDrop(GLFWwindow* window, int count, const char** paths);

  GLFWwindow* window_ = nullptr;
  std::vector<InputEvent> events_;
};

}  // namespace fibscope
