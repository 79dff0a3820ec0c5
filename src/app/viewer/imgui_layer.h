// Dear ImGui on the viewer's presentation image: the context, the GLFW
// platform backend when there is a window (offscreen, the display size and
// time step are set here and there is no platform backend), the Vulkan
// renderer backend drawing in the presentation's render pass, and the font
// atlas upload.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "gpu/vulkan_context.h"

struct GLFWwindow;
struct ImGuiContext;

namespace fibscope {

class ImGuiLayer {
 public:
  // `window` null: offscreen. Throws Error when the backend cannot start.
  ImGuiLayer(const gpu::VulkanContext& context, VkRenderPass render_pass, GLFWwindow* window);
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  // Starts a UI frame for a width x height presentation image, dt seconds
  // after the last one.
  void newFrame(uint32_t width, uint32_t height, double dt_seconds);
  // Ends the UI frame and records its draws (inside the presentation pass).
  void record(VkCommandBuffer cmd);
  // ImGui wants the mouse / keyboard this frame (over a panel, typing).
  bool wantsMouse() const;
  bool wantsKeyboard() const;

 private:
  void release();

  const gpu::VulkanContext& context_;
  ImGuiContext* imgui_ = nullptr;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  bool platform_ = false;  // the GLFW backend is running
  bool renderer_ = false;  // the Vulkan backend is running
};

}  // namespace fibscope
