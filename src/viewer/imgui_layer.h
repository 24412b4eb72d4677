// ImGui on GLFW + Vulkan (the backends Debian ships as sources, compiled into plume_viewer):
// context, descriptor pool, font upload; draws into the swapchain's render pass.
#pragma once

#include "gpu/context.h"
#include "viewer/swapchain.h"
#include "viewer/window.h"

namespace plume::viewer {

class ImGuiLayer {
 public:
  ImGuiLayer(gpu::Context& ctx, const Window& window, const Swapchain& swapchain);
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  void newFrame();
  void endFrame();                       // ImGui::Render()
  void record(VkCommandBuffer cmd);      // inside the render pass
  bool wantsMouse() const;
  bool wantsKeyboard() const;

 private:
  gpu::Context& ctx_;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
};

}  // namespace plume::viewer
