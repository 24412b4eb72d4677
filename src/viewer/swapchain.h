// The window's swapchain, a render pass that draws the UI over what the display pass copied into
// the image (load, not clear), and one frame in flight: acquire -> record -> submit -> present.
// Recreated when the window size changes or the surface reports it out of date.
#pragma once

#include "gpu/context.h"

#include <vulkan/vulkan.h>

#include <glm/vec2.hpp>

#include <optional>
#include <vector>

namespace plume::viewer {

class Swapchain {
 public:
  Swapchain(gpu::Context& ctx, glm::ivec2 size);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  VkFormat format() const { return format_; }
  bool bgra() const;  // byte order of the format: B, G, R, A
  VkExtent2D extent() const { return extent_; }
  uint32_t imageCount() const { return uint32_t(images_.size()); }
  uint32_t minImageCount() const { return minImages_; }
  VkPresentModeKHR presentMode() const { return presentMode_; }
  VkRenderPass renderPass() const { return renderPass_; }
  VkImage image(uint32_t i) const { return images_[i]; }
  VkFramebuffer framebuffer(uint32_t i) const { return framebuffers_[i]; }
  bool canReadBack() const { return canReadBack_; }  // images have TRANSFER_SRC usage

  void recreate(glm::ivec2 size);
  // Waits for the previous frame, acquires the next image; nullopt when the swapchain had to be
  // recreated (skip this frame).
  std::optional<uint32_t> acquire(glm::ivec2 windowSize);
  VkCommandBuffer commandBuffer() const { return cmd_; }  // begun by acquire()
  // Ends the command buffer, submits it and presents; recreates the swapchain when out of date.
  void submitAndPresent(uint32_t index, glm::ivec2 windowSize);
  void waitForFrame();  // the last submitted frame has completed

 private:
  void create(glm::ivec2 size);
  void destroySwapchain();

  gpu::Context& ctx_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkColorSpaceKHR colorSpace_ = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  VkPresentModeKHR presentMode_ = VK_PRESENT_MODE_FIFO_KHR;
  VkExtent2D extent_{};
  uint32_t minImages_ = 2;
  bool canReadBack_ = false;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  std::vector<VkSemaphore> renderDone_;  // per image: presentation waits on it
  VkSemaphore imageReady_ = VK_NULL_HANDLE;
  VkFence inFlight_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
};

}  // namespace plume::viewer
