// The display step: the renderer's linear image -> tone map (shaders/viewer/display.comp, once per
// image pixel, written to the window pixels that show it) into a packed 8-bit buffer the size of
// the window -> vkCmdCopyBufferToImage into the swapchain image.
// Also reads a presented image back (scripted tests compare it with the screenshot).
#pragma once

#include "gpu/pipeline.h"
#include "gpu/shader_compiler.h"
#include "io/image.h"

#include <vulkan/vulkan.h>

#include <memory>
#include <vector>

namespace plume::viewer {

class DisplayPass {
 public:
  DisplayPass(gpu::Context& ctx, gpu::ShaderCompiler& compiler);

  // Reads the renderer's accumulation buffer in place (render/gpu_scene.h readAccumulation's
  // layout: the mean RGB in every other vec4). The buffer must outlive the recorded frames.
  void setSource(const gpu::Buffer& accumulation, int width, int height);
  // Records the tone map and the copy; leaves `target` in TRANSFER_DST_OPTIMAL (its previous
  // contents are discarded).
  void record(VkCommandBuffer cmd, VkImage target, VkExtent2D extent, bool bgra, float exposureStops,
              gpu::GpuTimer* timer);

 private:
  gpu::Context& ctx_;
  std::unique_ptr<gpu::ComputePass> pass_;
  VkBuffer src_ = VK_NULL_HANDLE;  // the bound source (owned by the renderer)
  gpu::Buffer dst_;
  int srcWidth_ = 0, srcHeight_ = 0;
};

// Copies a presented swapchain image (PRESENT_SRC layout, after the frame's render pass) into a
// host buffer and back to PRESENT_SRC; call `pixels` after the frame's fence.
class ImageReadback {
 public:
  explicit ImageReadback(gpu::Context& ctx) : ctx_(ctx) {}
  void record(VkCommandBuffer cmd, VkImage image, VkExtent2D extent);
  // RGB8 rows, top first.
  std::vector<unsigned char> pixels(bool bgra) const;
  VkExtent2D extent() const { return extent_; }

 private:
  gpu::Context& ctx_;
  gpu::Buffer buffer_;
  VkExtent2D extent_{};
};

// An 8-bit RGB PNG from raw pixels (the window as shown; no tone mapping). Throws InputError.

}  // namespace plume::viewer
