// RAII Vulkan resources: buffers and 3D images with their memory. Move-only.
// Memory: device-local and host-visible when the device has it (lavapipe, resizable BAR), else
// device-local with staging copies through Context::submitAndWait.
#pragma once

#include "gpu/context.h"

#include <glm/vec3.hpp>
#include <vulkan/vulkan.h>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace plume::gpu {

enum class MemoryUse {
  Device,   // device-local, host-visible too where the device offers it
  Staging,  // host-visible and coherent (transfers)
};

class Buffer {
 public:
  Buffer() = default;
  // `name` appears in errors (e.g. a buffer larger than the device allows: an InputError, since the
  // sizes follow from the input).
  Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, const std::string& name,
         MemoryUse use = MemoryUse::Device);
  ~Buffer();
  Buffer(Buffer&& o) noexcept { *this = std::move(o); }
  Buffer& operator=(Buffer&& o) noexcept;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  bool valid() const { return buffer_ != VK_NULL_HANDLE; }

  void upload(const void* data, size_t bytes, size_t offset = 0);
  void download(void* data, size_t bytes, size_t offset = 0) const;
  void fillZero();

 private:
  void release();
  Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;  // persistently mapped when host-visible
};

// A read-only array that shaders read with texelFetch (a uniform texel buffer: `samplerBuffer`,
// `usamplerBuffer`), one 32-bit texel per element. Per-lane reads of a storage buffer are a scalar
// loop over the lanes on a SIMD back end such as lavapipe; a texel fetch is one gather
// (docs/architecture.md, "Descriptor kinds").
class TexelBuffer {
 public:
  TexelBuffer() = default;
  // `format`: VK_FORMAT_R32_SFLOAT, VK_FORMAT_R32_UINT (4 bytes per element),
  // VK_FORMAT_R32G32B32A32_SFLOAT or _UINT (16); `count` elements, uploaded from `data` where
  // not null. `storage`: a storage texel buffer (imageBuffer, read and written; zeroed with
  // fillZero) instead of a uniform one (samplerBuffer, read only); its view may then also be bound
  // as a uniform texel buffer. `alsoStorageBuffer` (with `storage`): its buffer() may be bound as
  // a storage buffer too (the path tracer's slots: written word by word, read a texel at a time),
  // which bounds its size by the device's storage buffer range, not only its texel count (a
  // storage texel buffer alone holds up to maxTexelBufferElements texels: lavapipe's 2^27 texels
  // are 2 GiB, its storage buffers 128 MiB; ReSTIR's per-pixel arrays need the former at 720p).
  TexelBuffer(Context& ctx, const void* data, size_t count, VkFormat format, const std::string& name,
              bool storage = false, bool alsoStorageBuffer = false);
  ~TexelBuffer();
  TexelBuffer(TexelBuffer&& o) noexcept { *this = std::move(o); }
  TexelBuffer& operator=(TexelBuffer&& o) noexcept;

  VkBufferView view() const { return view_; }
  const Buffer& buffer() const { return buffer_; }
  void fillZero() { buffer_.fillZero(); }
  void upload(const void* data, size_t bytes) { buffer_.upload(data, bytes); }  // from the first texel

 private:
  void release();
  Context* ctx_ = nullptr;
  Buffer buffer_;
  VkBufferView view_ = VK_NULL_HANDLE;
};

// A sampled 3D image, read with texelFetch (exact, unfiltered) or, where the format allows
// linear filtering, with texture() through the texture unit's trilinear filter: its sampler is
// linear when the format can be filtered (texelFetch ignores the filter), nearest otherwise.
class Image3D {
 public:
  Image3D() = default;
  Image3D(Context& ctx, glm::ivec3 extent, VkFormat format, size_t texelBytes, const std::string& name);
  ~Image3D();
  Image3D(Image3D&& o) noexcept { *this = std::move(o); }
  Image3D& operator=(Image3D&& o) noexcept;

  void upload(const void* data, size_t bytes);
  VkImageView view() const { return view_; }
  VkSampler sampler() const { return sampler_; }
  glm::ivec3 extent() const { return extent_; }
  bool linearFilter() const { return linear_; }  // texture() filters (the format allows it)

 private:
  void release();
  Context* ctx_ = nullptr;
  bool linear_ = false;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkSampler sampler_ = VK_NULL_HANDLE;
  glm::ivec3 extent_{0};
  size_t texelBytes_ = 0;
};

// What an estimator allocates per pixel of its image: storage buffers (name, bytes per pixel),
// each of which must fit the device's largest storage buffer (maxStorageBufferRange; lavapipe
// 128 MiB), and storage texel buffers (name, texels per pixel), each within maxTexelBufferElements
// (lavapipe 2^27).
struct PerPixelBuffers {
  std::vector<std::pair<std::string, size_t>> storageBytes;
  std::vector<std::pair<std::string, size_t>> texels;
};
// Throws InputError where a width x height image does not fit, naming `what`, the buffer that
// allows the fewest pixels, that number, an image of the same aspect that fits every buffer, and
// `remedy` (what else the user can change); call it before anything is compiled or allocated.
void requirePerPixelStorage(const Context& ctx, const std::string& what, const PerPixelBuffers& buffers, int width,
                            int height, const std::string& remedy);

// A layout transition of a whole single-mip colour image.
void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags srcAccess,
                  VkAccessFlags dstAccess, VkPipelineStageFlags srcStage, VkPipelineStageFlags dstStage);

}  // namespace plume::gpu
