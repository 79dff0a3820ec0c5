#include "app/viewer/imgui_layer.h"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_vulkan.h>

#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "gpu/submit.h"
#include "gpu/vk_check.h"

namespace fibscope {
namespace {

// ImGui's backend reports Vulkan failures through this; they mean a bug or a
// lost device, as VK_CHECK does.
void checkImGuiVkResult(VkResult result) {
  if (result != VK_SUCCESS) gpu::vkCheckFailed("ImGui Vulkan backend", result, __FILE__, __LINE__);
}

}  // namespace

ImGuiLayer::ImGuiLayer(const gpu::VulkanContext& context, VkRenderPass render_pass, GLFWwindow* window)
    : context_(context) {
  IMGUI_CHECKVERSION();
  imgui_ = ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini written into the working directory
  ImGui::StyleColorsDark();
  ImGui::GetStyle().WindowRounding = 4.0f;
  try {
    if (window) {
      if (!ImGui_ImplGlfw_InitForVulkan(window, true)) throw Error("imgui: the GLFW backend cannot start");
      platform_ = true;
    } else {
      io.BackendPlatformName = "fibscope offscreen";
    }
    // The font atlas is the only texture ImGui samples.
    const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 4}};
    VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool_info.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    pool_info.maxSets = 4;
    pool_info.poolSizeCount = 1;
    pool_info.pPoolSizes = sizes;
    gpu::throwIfFailed(vkCreateDescriptorPool(context.device(), &pool_info, nullptr, &pool_),
                       "vkCreateDescriptorPool (ImGui)");

    ImGui_ImplVulkan_InitInfo info{};
    info.Instance = context.instance().handle();
    info.PhysicalDevice = context.physicalDevice();
    info.Device = context.device();
    info.QueueFamily = context.queueFamily();
    info.Queue = context.queue();
    info.DescriptorPool = pool_;
    info.Subpass = 0;
    // Its vertex buffers rotate over ImageCount frames; one frame is in
    // flight, so two are plenty whatever the swapchain has.
    info.MinImageCount = 2;
    info.ImageCount = 2;
    info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    info.CheckVkResultFn = checkImGuiVkResult;
    if (!ImGui_ImplVulkan_Init(&info, render_pass)) throw Error("imgui: the Vulkan backend cannot start");
    renderer_ = true;
    gpu::submitOnce(context, [](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
    ImGui_ImplVulkan_DestroyFontUploadObjects();
  } catch (...) {
    release();
    throw;
  }
}

ImGuiLayer::~ImGuiLayer() { release(); }

void ImGuiLayer::release() {
  if (context_.device() != VK_NULL_HANDLE) vkDeviceWaitIdle(context_.device());
  if (renderer_) ImGui_ImplVulkan_Shutdown();
  renderer_ = false;
  if (platform_) ImGui_ImplGlfw_Shutdown();
  platform_ = false;
  if (pool_ != VK_NULL_HANDLE) vkDestroyDescriptorPool(context_.device(), pool_, nullptr);
  pool_ = VK_NULL_HANDLE;
  if (imgui_) ImGui::DestroyContext(imgui_);
  imgui_ = nullptr;
}

void ImGuiLayer::newFrame(uint32_t width, uint32_t height, double dt_seconds) {
  ImGui_ImplVulkan_NewFrame();
  ImGuiIO& io = ImGui::GetIO();
  if (platform_) {
    ImGui_ImplGlfw_NewFrame();
  } else {
    io.DisplaySize = ImVec2(float(width), float(height));
    io.DisplayFramebufferScale = ImVec2(1, 1);
  }
  // Both paths: the frame loop's own clock (GLFW's would do for a window,
  // but offscreen frames need one too, and it must be > 0).
  io.DeltaTime = float(dt_seconds > 1e-6 ? dt_seconds : 1e-6);
  ImGui::NewFrame();
}

void ImGuiLayer::record(VkCommandBuffer cmd) {
  ImGui::Render();
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd);
}

bool ImGuiLayer::wantsMouse() const { return ImGui::GetIO().WantCaptureMouse; }
bool ImGuiLayer::wantsKeyboard() const { return ImGui::GetIO().WantCaptureKeyboard; }

}  // namespace fibscope
