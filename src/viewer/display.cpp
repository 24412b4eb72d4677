#include "viewer/display.h"

#include "core/error.h"
#include "core/log.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace plume::viewer {
namespace {

struct DisplayPush {  // matches `Push` in shaders/viewer/display.comp
  glm::uvec4 size;
  glm::vec4 fit;
  glm::uvec4 flags;
};
static_assert(sizeof(DisplayPush) == 48);

}  // namespace

DisplayPass::DisplayPass(gpu::Context& ctx, gpu::ShaderCompiler& compiler) : ctx_(ctx) {
  using gpu::BindingType;
  pass_ = std::make_unique<gpu::ComputePass>(ctx, compiler.compile("viewer/display.comp", {}),
                                             std::vector<BindingType>{BindingType::StorageBuffer, BindingType::StorageBuffer},
                                             uint32_t(sizeof(DisplayPush)), "display", glm::uvec3(16, 16, 1));
}

void DisplayPass::setSource(const gpu::Buffer& accumulation, int width, int height) {
  pass_->set.bind(0, accumulation);  // every time: a rebuilt renderer may reuse a freed handle
  src_ = accumulation.handle();
  srcWidth_ = width;
  srcHeight_ = height;
}

void DisplayPass::record(VkCommandBuffer cmd, VkImage target, VkExtent2D extent, bool bgra, float exposureStops,
                         gpu::GpuTimer* timer) {
  PLUME_CHECK_MSG(src_ != VK_NULL_HANDLE, "DisplayPass::record before setSource");
  const VkDeviceSize bytes = VkDeviceSize(extent.width) * extent.height * 4;
  if (!dst_.valid() || dst_.size() != bytes) {
    dst_ = gpu::Buffer(ctx_, bytes,
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                       "display target");
    pass_->set.bind(1, dst_);
  }
  // Fit the image into the window, aspect kept: `scale` source pixels per window pixel.
  const float scale = std::max(float(srcWidth_) / float(extent.width), float(srcHeight_) / float(extent.height));
  DisplayPush push{};
  push.size = glm::uvec4(uint32_t(srcWidth_), uint32_t(srcHeight_), extent.width, extent.height);
  push.fit = glm::vec4(0.5f * (float(extent.width) - float(srcWidth_) / scale),
                       0.5f * (float(extent.height) - float(srcHeight_) / scale), scale, std::exp2(exposureStops));
  push.flags = glm::uvec4(bgra ? 1u : 0u, 0u, 0u, 0u);
  // Opaque black first, for the border the fitted image leaves: the pass writes only the window
  // pixels that show a source pixel (one invocation per source pixel: shaders/viewer/display.comp).
  // (A fill of the whole window costs nothing measurable next to the pass.)
  vkCmdFillBuffer(cmd, dst_.handle(), 0, bytes, 0xff000000u);
  gpu::computeBarrier(cmd);
  pass_->record(cmd, glm::uvec3(uint32_t(srcWidth_), uint32_t(srcHeight_), 1), &push, timer);
  gpu::computeBarrier(cmd);
  gpu::imageBarrier(cmd, target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
               VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {extent.width, extent.height, 1};
  vkCmdCopyBufferToImage(cmd, dst_.handle(), target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
}

void ImageReadback::record(VkCommandBuffer cmd, VkImage image, VkExtent2D extent) {
  const VkDeviceSize bytes = VkDeviceSize(extent.width) * extent.height * 4;
  if (!buffer_.valid() || buffer_.size() != bytes) {
    buffer_ = gpu::Buffer(ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "window readback", gpu::MemoryUse::Staging);
  }
  extent_ = extent;
  gpu::imageBarrier(cmd, image, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {extent.width, extent.height, 1};
  vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer_.handle(), 1, &region);
  gpu::imageBarrier(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
               VK_ACCESS_TRANSFER_READ_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
}

std::vector<unsigned char> ImageReadback::pixels(bool bgra) const {
  const size_t n = size_t(extent_.width) * extent_.height;
  std::vector<unsigned char> raw(4 * n), rgb(3 * n);
  buffer_.download(raw.data(), raw.size());
  for (size_t i = 0; i < n; ++i) {
    rgb[3 * i + 0] = raw[4 * i + (bgra ? 2 : 0)];
    rgb[3 * i + 1] = raw[4 * i + 1];
    rgb[3 * i + 2] = raw[4 * i + (bgra ? 0 : 2)];
  }
  return rgb;
}


}  // namespace plume::viewer
