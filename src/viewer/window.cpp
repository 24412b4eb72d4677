#include "viewer/window.h"

#include "core/error.h"
#include "core/log.h"
#include "gpu/check.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

namespace plume::viewer {
namespace {

std::string g_lastGlfwError;

void onGlfwError(int code, const char* text) { g_lastGlfwError = strf("GLFW error 0x%x: %s", code, text); }

}  // namespace

Window::Window(glm::ivec2 size, const std::string& title) {
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit()) {
    throw DeviceError("no display for the viewer window (" + g_lastGlfwError +
                      "); on a machine without a screen run it under xvfb-run");
  }
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    throw DeviceError("GLFW finds no Vulkan loader able to present (" + g_lastGlfwError + ")");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(size.x, size.y, title.c_str(), nullptr, nullptr);
  if (!window_) {
    glfwTerminate();
    throw DeviceError("cannot open the viewer window (" + g_lastGlfwError + ")");
  }
}

Window::~Window() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

std::vector<std::string> Window::instanceExtensions() const {
  uint32_t n = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&n);
  std::vector<std::string> out;
  for (uint32_t i = 0; i < n; ++i) out.emplace_back(names[i]);
  return out;
}

VkSurfaceKHR Window::createSurface(VkInstance instance) const {
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkResult r = glfwCreateWindowSurface(instance, window_, nullptr, &surface);
  if (r != VK_SUCCESS) throw DeviceError(strf("glfwCreateWindowSurface failed: %s", gpu::vkResultName(r)));
  return surface;
}

glm::ivec2 Window::framebufferSize() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return {w, h};
}

bool Window::shouldClose() const { return glfwWindowShouldClose(window_); }
void Window::requestClose() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }

}  // namespace plume::viewer
