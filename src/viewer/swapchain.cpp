#include "viewer/swapchain.h"

#include "core/error.h"
#include "core/log.h"
#include "gpu/check.h"

#include <algorithm>

namespace plume::viewer {
namespace {

VkSurfaceFormatKHR chooseFormat(VkPhysicalDevice pd, VkSurfaceKHR surface) {
  uint32_t n = 0;
  PLUME_VK(vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface, &n, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(n);
  PLUME_VK(vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface, &n, formats.data()));
  if (formats.empty()) throw DeviceError("the window surface offers no formats");
  // UNORM: the display pass writes sRGB-encoded bytes itself, and the UI's colours assume it.
  for (VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB}) {
    for (const auto& f : formats) {
      if (f.format == want && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
    }
  }
  throw DeviceError(strf("the window surface offers no 8-bit RGBA/BGRA format (first: %d)", int(formats[0].format)));
}

VkPresentModeKHR choosePresentMode(VkPhysicalDevice pd, VkSurfaceKHR surface) {
  uint32_t n = 0;
  PLUME_VK(vkGetPhysicalDeviceSurfacePresentModesKHR(pd, surface, &n, nullptr));
  std::vector<VkPresentModeKHR> modes(n);
  PLUME_VK(vkGetPhysicalDeviceSurfacePresentModesKHR(pd, surface, &n, modes.data()));
  // Progressive rendering wants every frame it can get without tearing: mailbox, else FIFO.
  for (VkPresentModeKHR m : modes) {
    if (m == VK_PRESENT_MODE_MAILBOX_KHR) return m;
  }
  return VK_PRESENT_MODE_FIFO_KHR;
}

}  // namespace

Swapchain::Swapchain(gpu::Context& ctx, glm::ivec2 size) : ctx_(ctx) {
  if (!ctx.presents()) throw DeviceError("Swapchain needs a gpu::Context created with a surface");
  const VkSurfaceFormatKHR sf = chooseFormat(ctx.physicalDevice(), ctx.surface());
  format_ = sf.format;
  colorSpace_ = sf.colorSpace;
  presentMode_ = choosePresentMode(ctx.physicalDevice(), ctx.surface());

  VkAttachmentDescription color{};
  color.format = format_;
  color.samples = VK_SAMPLE_COUNT_1_BIT;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;  // keep the rendered image, draw the UI over it
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  color.initialLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;  // after the display copy
  color.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &ref;
  VkSubpassDependency dep{};
  dep.srcSubpass = VK_SUBPASS_EXTERNAL;
  dep.dstSubpass = 0;
  dep.srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dep.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  dep.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dep.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rp.attachmentCount = 1;
  rp.pAttachments = &color;
  rp.subpassCount = 1;
  rp.pSubpasses = &sub;
  rp.dependencyCount = 1;
  rp.pDependencies = &dep;
  PLUME_VK(vkCreateRenderPass(ctx.device(), &rp, nullptr, &renderPass_));

  VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  PLUME_VK(vkCreateSemaphore(ctx.device(), &si, nullptr, &imageReady_));
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  PLUME_VK(vkCreateFence(ctx.device(), &fi, nullptr, &inFlight_));
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = ctx.commandPool();
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  PLUME_VK(vkAllocateCommandBuffers(ctx.device(), &ai, &cmd_));
  create(size);
}

Swapchain::~Swapchain() {
  VkDevice d = ctx_.device();
  vkDeviceWaitIdle(d);
  destroySwapchain();
  if (swapchain_) vkDestroySwapchainKHR(d, swapchain_, nullptr);
  vkFreeCommandBuffers(d, ctx_.commandPool(), 1, &cmd_);
  vkDestroyFence(d, inFlight_, nullptr);
  vkDestroySemaphore(d, imageReady_, nullptr);
  vkDestroyRenderPass(d, renderPass_, nullptr);
}

bool Swapchain::bgra() const { return format_ == VK_FORMAT_B8G8R8A8_UNORM || format_ == VK_FORMAT_B8G8R8A8_SRGB; }

void Swapchain::destroySwapchain() {
  VkDevice d = ctx_.device();
  for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(d, f, nullptr);
  for (VkImageView v : views_) vkDestroyImageView(d, v, nullptr);
  for (VkSemaphore s : renderDone_) vkDestroySemaphore(d, s, nullptr);
  framebuffers_.clear();
  views_.clear();
  renderDone_.clear();
  images_.clear();
}

void Swapchain::create(glm::ivec2 size) {
  VkDevice d = ctx_.device();
  VkSurfaceCapabilitiesKHR caps;
  PLUME_VK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_.physicalDevice(), ctx_.surface(), &caps));
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
    throw DeviceError(ctx_.deviceName() + ": swapchain images cannot be transfer destinations");
  }
  extent_ = caps.currentExtent;
  if (extent_.width == 0xFFFFFFFFu) {
    extent_.width = std::clamp(uint32_t(std::max(1, size.x)), caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height = std::clamp(uint32_t(std::max(1, size.y)), caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  minImages_ = std::max(2u, caps.minImageCount);
  uint32_t count = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);
  canReadBack_ = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;

  VkSwapchainKHR old = swapchain_;
  VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  ci.surface = ctx_.surface();
  ci.minImageCount = count;
  ci.imageFormat = format_;
  ci.imageColorSpace = colorSpace_;
  ci.imageExtent = extent_;
  ci.imageArrayLayers = 1;
  ci.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                  (canReadBack_ ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
  ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.preTransform = caps.currentTransform;
  ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  ci.presentMode = presentMode_;
  ci.clipped = VK_TRUE;
  ci.oldSwapchain = old;
  PLUME_VK(vkCreateSwapchainKHR(d, &ci, nullptr, &swapchain_));
  if (old) vkDestroySwapchainKHR(d, old, nullptr);

  uint32_t n = 0;
  PLUME_VK(vkGetSwapchainImagesKHR(d, swapchain_, &n, nullptr));
  images_.resize(n);
  PLUME_VK(vkGetSwapchainImagesKHR(d, swapchain_, &n, images_.data()));
  for (VkImage image : images_) {
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format_;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view;
    PLUME_VK(vkCreateImageView(d, &vi, nullptr, &view));
    views_.push_back(view);
    VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = renderPass_;
    fb.attachmentCount = 1;
    fb.pAttachments = &view;
    fb.width = extent_.width;
    fb.height = extent_.height;
    fb.layers = 1;
    VkFramebuffer framebuffer;
    PLUME_VK(vkCreateFramebuffer(d, &fb, nullptr, &framebuffer));
    framebuffers_.push_back(framebuffer);
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore s;
    PLUME_VK(vkCreateSemaphore(d, &si, nullptr, &s));
    renderDone_.push_back(s);
  }
}

void Swapchain::recreate(glm::ivec2 size) {
  vkDeviceWaitIdle(ctx_.device());
  destroySwapchain();
  create(size);
}

void Swapchain::waitForFrame() { PLUME_VK(vkWaitForFences(ctx_.device(), 1, &inFlight_, VK_TRUE, UINT64_MAX)); }

std::optional<uint32_t> Swapchain::acquire(glm::ivec2 windowSize) {
  waitForFrame();
  if (windowSize.x > 0 && windowSize.y > 0 &&
      (uint32_t(windowSize.x) != extent_.width || uint32_t(windowSize.y) != extent_.height)) {
    recreate(windowSize);
  }
  uint32_t index = 0;
  VkResult r = vkAcquireNextImageKHR(ctx_.device(), swapchain_, UINT64_MAX, imageReady_, VK_NULL_HANDLE, &index);
  if (r == VK_ERROR_OUT_OF_DATE_KHR) {
    recreate(windowSize);
    return std::nullopt;
  }
  if (r != VK_SUCCESS && r != VK_SUBOPTIMAL_KHR) gpu::throwVkError(r, "vkAcquireNextImageKHR", __FILE__, __LINE__);
  PLUME_VK(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  PLUME_VK(vkBeginCommandBuffer(cmd_, &bi));
  return index;
}

void Swapchain::submitAndPresent(uint32_t index, glm::ivec2 windowSize) {
  PLUME_VK(vkEndCommandBuffer(cmd_));
  const VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;  // the first write is the copy
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &imageReady_;
  si.pWaitDstStageMask = &waitStage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &renderDone_[index];
  PLUME_VK(vkResetFences(ctx_.device(), 1, &inFlight_));
  PLUME_VK(vkQueueSubmit(ctx_.queue(), 1, &si, inFlight_));
  VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  pi.waitSemaphoreCount = 1;
  pi.pWaitSemaphores = &renderDone_[index];
  pi.swapchainCount = 1;
  pi.pSwapchains = &swapchain_;
  pi.pImageIndices = &index;
  VkResult r = vkQueuePresentKHR(ctx_.queue(), &pi);
  if (r == VK_ERROR_OUT_OF_DATE_KHR || r == VK_SUBOPTIMAL_KHR) {
    recreate(windowSize);
  } else if (r != VK_SUCCESS) {
    gpu::throwVkError(r, "vkQueuePresentKHR", __FILE__, __LINE__);
  }
}

}  // namespace plume::viewer
