// A GLFW window without a client API (Vulkan draws into it), and the pieces gpu::Context needs
// to present to it: the instance extensions and a surface factory.
#pragma once

#include <vulkan/vulkan.h>

#include <glm/vec2.hpp>

#include <string>
#include <vector>

struct GLFWwindow;

namespace plume::viewer {

class Window {
 public:
  // Throws DeviceError when there is no display (message says how to run headless: xvfb-run).
  Window(glm::ivec2 size, const std::string& title);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  GLFWwindow* handle() const { return window_; }
  std::vector<std::string> instanceExtensions() const;
  VkSurfaceKHR createSurface(VkInstance instance) const;  // throws DeviceError
  glm::ivec2 framebufferSize() const;
  bool shouldClose() const;
  void requestClose();

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace plume::viewer
