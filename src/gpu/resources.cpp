#include "gpu/resources.h"

#include "core/error.h"
#include "core/log.h"
#include "gpu/check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace plume::gpu {

namespace {
constexpr const char* kTooLargeHint = "the input is too large for this device: a smaller image or a smaller or "
                                      "coarser volume, or a device with larger limits (--device)";
}  // namespace

// ---------------------------------------------------------------------------------------------
Buffer::Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, const std::string& name,
               MemoryUse use)
    : ctx_(&ctx), size_(size) {
  if (size == 0) size = size_ = 4;  // Vulkan forbids empty buffers; an empty array binds 4 bytes
  // Beyond a limit of the device: the size follows from the input (image size, volume), so the
  // same input fails the same way on this device every time: bad input, not a device failure.
  if ((usage & VK_BUFFER_USAGE_STORAGE_BUFFER_BIT) && size > ctx.limits().maxStorageBufferRange) {
    throw InputError(strf("%s: %s needs %.1f MiB, more than the device's storage buffer limit of %.1f MiB (%s)",
                          ctx.deviceName().c_str(), name.c_str(), size / 1048576.0,
                          ctx.limits().maxStorageBufferRange / 1048576.0, kTooLargeHint));
  }
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = size;
  bi.usage = usage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  PLUME_VK(vkCreateBuffer(ctx.device(), &bi, nullptr, &buffer_));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx.device(), buffer_, &req);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  ai.memoryTypeIndex = use == MemoryUse::Staging
                           ? ctx.findMemoryType(req.memoryTypeBits, host)
                           : ctx.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, host);
  VkResult r = vkAllocateMemory(ctx.device(), &ai, nullptr, &memory_);
  if (r != VK_SUCCESS) {
    release();
    throw DeviceError(strf("%s: cannot allocate %.1f MiB for %s (%s)", ctx.deviceName().c_str(),
                           req.size / 1048576.0, name.c_str(), vkResultName(r)));
  }
  PLUME_VK(vkBindBufferMemory(ctx.device(), buffer_, memory_, 0));
  if ((ctx.memoryTypeFlags(ai.memoryTypeIndex) & host) == host) {
    PLUME_VK(vkMapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
  }
}

Buffer::~Buffer() { release(); }

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    release();
    ctx_ = std::exchange(o.ctx_, nullptr);
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(o.size_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
  }
  return *this;
}

void Buffer::release() {
  if (!ctx_) return;
  if (buffer_) vkDestroyBuffer(ctx_->device(), buffer_, nullptr);
  if (memory_) vkFreeMemory(ctx_->device(), memory_, nullptr);
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

void Buffer::upload(const void* data, size_t bytes, size_t offset) {
  PLUME_CHECK(offset + bytes <= size_);
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "staging", MemoryUse::Staging);
  PLUME_CHECK(staging.mapped_);
  std::memcpy(staging.mapped_, data, bytes);
  ctx_->submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, offset, bytes};
    vkCmdCopyBuffer(cmd, staging.buffer_, buffer_, 1, &region);
  });
}

void Buffer::download(void* data, size_t bytes, size_t offset) const {
  PLUME_CHECK(offset + bytes <= size_);
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "staging", MemoryUse::Staging);
  PLUME_CHECK(staging.mapped_);
  ctx_->submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{offset, 0, bytes};
    vkCmdCopyBuffer(cmd, buffer_, staging.buffer_, 1, &region);
  });
  std::memcpy(data, staging.mapped_, bytes);
}

void Buffer::fillZero() {
  ctx_->submitAndWait([&](VkCommandBuffer cmd) { vkCmdFillBuffer(cmd, buffer_, 0, VK_WHOLE_SIZE, 0); });
}

// ---------------------------------------------------------------------------------------------
TexelBuffer::TexelBuffer(Context& ctx, const void* data, size_t count, VkFormat format, const std::string& name,
                         bool storage, bool alsoStorageBuffer)
    : ctx_(&ctx) {
  PLUME_CHECK(format == VK_FORMAT_R32_SFLOAT || format == VK_FORMAT_R32_UINT ||
              format == VK_FORMAT_R32G32B32A32_SFLOAT || format == VK_FORMAT_R32G32B32A32_UINT);
  const size_t texelBytes = format == VK_FORMAT_R32_SFLOAT || format == VK_FORMAT_R32_UINT ? 4 : 16;
  const size_t given = count;
  if (count == 0) count = 1;  // Vulkan forbids empty buffers; an empty array binds one texel
  if (count > ctx.limits().maxTexelBufferElements) {
    throw InputError(strf("%s: %s needs %zu elements, more than the device's texel buffer limit of %u (%s)",
                          ctx.deviceName().c_str(), name.c_str(), count, ctx.limits().maxTexelBufferElements,
                          kTooLargeHint));
  }
  buffer_ = Buffer(ctx, count * texelBytes,
                   storage ? VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
                                 (alsoStorageBuffer ? VkBufferUsageFlags(VK_BUFFER_USAGE_STORAGE_BUFFER_BIT) : 0u)
                           : VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT,
                   name);
  if (data && given > 0) buffer_.upload(data, given * texelBytes);
  VkBufferViewCreateInfo vi{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  vi.buffer = buffer_.handle();
  vi.format = format;
  vi.offset = 0;
  vi.range = VK_WHOLE_SIZE;
  PLUME_VK(vkCreateBufferView(ctx.device(), &vi, nullptr, &view_));
}

TexelBuffer::~TexelBuffer() { release(); }

TexelBuffer& TexelBuffer::operator=(TexelBuffer&& o) noexcept {
  if (this != &o) {
    release();
    ctx_ = std::exchange(o.ctx_, nullptr);
    buffer_ = std::move(o.buffer_);
    view_ = std::exchange(o.view_, VK_NULL_HANDLE);
  }
  return *this;
}

void TexelBuffer::release() {
  if (ctx_ && view_) vkDestroyBufferView(ctx_->device(), view_, nullptr);
  view_ = VK_NULL_HANDLE;
  buffer_ = Buffer();
}

// ---------------------------------------------------------------------------------------------
Image3D::Image3D(Context& ctx, glm::ivec3 extent, VkFormat format, size_t texelBytes, const std::string& name)
    : ctx_(&ctx), extent_(extent), texelBytes_(texelBytes) {
  const uint32_t maxSide = ctx.limits().maxImageDimension3D;
  if (uint32_t(extent.x) > maxSide || uint32_t(extent.y) > maxSide || uint32_t(extent.z) > maxSide) {
    throw InputError(strf("%s: %s needs a %dx%dx%d 3D image; the device allows %u per side (%s)",
                          ctx.deviceName().c_str(), name.c_str(), extent.x, extent.y, extent.z, maxSide, kTooLargeHint));
  }
  VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ii.imageType = VK_IMAGE_TYPE_3D;
  ii.format = format;
  ii.extent = {uint32_t(extent.x), uint32_t(extent.y), uint32_t(extent.z)};
  ii.mipLevels = 1;
  ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  PLUME_VK(vkCreateImage(ctx.device(), &ii, nullptr, &image_));
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(ctx.device(), image_, &req);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkResult r = vkAllocateMemory(ctx.device(), &ai, nullptr, &memory_);
  if (r != VK_SUCCESS) {
    release();
    throw DeviceError(strf("%s: cannot allocate %.1f MiB for %s (%s)", ctx.deviceName().c_str(),
                           req.size / 1048576.0, name.c_str(), vkResultName(r)));
  }
  PLUME_VK(vkBindImageMemory(ctx.device(), image_, memory_, 0));
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = image_;
  vi.viewType = VK_IMAGE_VIEW_TYPE_3D;
  vi.format = format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  PLUME_VK(vkCreateImageView(ctx.device(), &vi, nullptr, &view_));
  VkFormatProperties fp{};
  vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), format, &fp);
  linear_ = (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = linear_ ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
  si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  PLUME_VK(vkCreateSampler(ctx.device(), &si, nullptr, &sampler_));
}

Image3D::~Image3D() { release(); }

Image3D& Image3D::operator=(Image3D&& o) noexcept {
  if (this != &o) {
    release();
    ctx_ = std::exchange(o.ctx_, nullptr);
    linear_ = o.linear_;
    image_ = std::exchange(o.image_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    view_ = std::exchange(o.view_, VK_NULL_HANDLE);
    sampler_ = std::exchange(o.sampler_, VK_NULL_HANDLE);
    extent_ = o.extent_;
    texelBytes_ = o.texelBytes_;
  }
  return *this;
}

void Image3D::release() {
  if (!ctx_) return;
  VkDevice d = ctx_->device();
  if (sampler_) vkDestroySampler(d, sampler_, nullptr);
  if (view_) vkDestroyImageView(d, view_, nullptr);
  if (image_) vkDestroyImage(d, image_, nullptr);
  if (memory_) vkFreeMemory(d, memory_, nullptr);
  sampler_ = VK_NULL_HANDLE;
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
}

void Image3D::upload(const void* data, size_t bytes) {
  PLUME_CHECK(bytes == size_t(extent_.x) * extent_.y * extent_.z * texelBytes_);
  Buffer staging(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "image staging", MemoryUse::Staging);
  staging.upload(data, bytes);
  ctx_->submitAndWait([&](VkCommandBuffer cmd) {
    imageBarrier(cmd, image_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {uint32_t(extent_.x), uint32_t(extent_.y), uint32_t(extent_.z)};
    vkCmdCopyBufferToImage(cmd, staging.handle(), image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    imageBarrier(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
  });
}

void requirePerPixelStorage(const Context& ctx, const std::string& what, const PerPixelBuffers& buffers, int width,
                            int height, const std::string& remedy) {
  const size_t pixels = size_t(width) * size_t(height);
  // The buffer that allows the fewest pixels decides: the image suggested fits every buffer.
  struct Limiting {
    std::string name;
    size_t perPixel = 0, most = SIZE_MAX;
    uint64_t limit = 0;
    const char *unit = "", *kind = "", *scaled = "";
  } worst;
  auto consider = [&](const std::string& name, size_t perPixel, uint64_t limit, const char* unit, const char* kind,
                      const char* scaled) {
    if (perPixel == 0) return;
    const size_t most = size_t(limit / perPixel);
    if (most < worst.most) worst = {name, perPixel, most, limit, unit, kind, scaled};
  };
  for (const auto& [name, bytes] : buffers.storageBytes) {
    consider(name, bytes, ctx.limits().maxStorageBufferRange, "bytes", "storage buffer", "MiB");
  }
  for (const auto& [name, texels] : buffers.texels) {
    consider(name, texels, ctx.limits().maxTexelBufferElements, "texels", "texel buffer", "M texels");
  }
  if (pixels <= worst.most) return;
  // The largest image of this aspect with at most `most` pixels.
  const double scale = std::sqrt(double(worst.most) / double(pixels));
  int w = std::max(1, int(width * scale)), h = std::max(1, int(height * scale));
  while (size_t(w) * h > worst.most && w > 1 && h > 1) --(w >= h ? w : h);
  throw InputError(strf("%s: %s at %dx%d needs %.1f %s for its %s (%zu %s a pixel), more than the device's largest "
                        "%s (%.1f %s): at most %zu pixels on this device, e.g. %dx%d; %s",
                        ctx.deviceName().c_str(), what.c_str(), width, height,
                        double(pixels * worst.perPixel) / 1048576.0, worst.scaled, worst.name.c_str(), worst.perPixel,
                        worst.unit, worst.kind, double(worst.limit) / 1048576.0, worst.scaled, worst.most, w, h,
                        remedy.c_str()));
}

void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess,
                  VkAccessFlags dstAccess, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.oldLayout = from;
  b.newLayout = to;
  b.srcAccessMask = srcAccess;
  b.dstAccessMask = dstAccess;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

}  // namespace plume::gpu
