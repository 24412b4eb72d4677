// Compute pipelines, their descriptor sets, and a pass = pipeline + set + dispatch, timed with
// timestamp queries (GpuTimer). Descriptor bindings are given as a list: binding i has type
// bindings[i], all in set 0, all visible to the compute stage.
#pragma once

#include "gpu/context.h"
#include "gpu/resources.h"

#include <glm/vec3.hpp>
#include <vulkan/vulkan.h>

#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace plume::gpu {

// StorageBuffer: read-write arrays. UniformBuffer: a small parameter block that every lane reads
// at the same place (std140). TexelBuffer: a read-only array read per lane (gpu::TexelBuffer).
// StorageTexelBuffer: a read-write array of texels (imageBuffer; gpu::TexelBuffer made with
// `storage`), bounded by maxTexelBufferElements rather than maxStorageBufferRange.
enum class BindingType { StorageBuffer, UniformBuffer, SampledImage, TexelBuffer, StorageTexelBuffer };

// A pass's binding table: bindings 0 .. count-1 are storage buffers except those listed with
// another type (binding numbers are named in shaders/shared/bindings.h).
using BindingTypes = std::vector<std::pair<uint32_t, BindingType>>;
std::vector<BindingType> bindingTable(uint32_t count, const BindingTypes& others);

class ComputePipeline {
 public:
  ComputePipeline(Context& ctx, const std::vector<uint32_t>& spirv, std::vector<BindingType> bindings,
                  uint32_t pushConstantBytes, std::string name);
  ~ComputePipeline();
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  VkPipeline pipeline() const { return pipeline_; }
  VkPipelineLayout layout() const { return layout_; }
  VkDescriptorSetLayout setLayout() const { return setLayout_; }
  const std::vector<BindingType>& bindings() const { return bindings_; }
  uint32_t pushConstantBytes() const { return pushBytes_; }
  const std::string& name() const { return name_; }

 private:
  Context& ctx_;
  std::vector<BindingType> bindings_;
  uint32_t pushBytes_;
  std::string name_;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

class DescriptorSet {
 public:
  DescriptorSet(Context& ctx, const ComputePipeline& pipeline);
  ~DescriptorSet();
  DescriptorSet(const DescriptorSet&) = delete;
  DescriptorSet& operator=(const DescriptorSet&) = delete;

  void bind(uint32_t binding, const Buffer& buffer);
  void bind(uint32_t binding, const Image3D& image);
  void bind(uint32_t binding, const TexelBuffer& buffer);
  VkDescriptorSet handle() const { return set_; }

 private:
  void write(uint32_t binding, std::initializer_list<BindingType> allowed, const VkDescriptorImageInfo* image,
             const VkDescriptorBufferInfo* buffer, const VkBufferView* texels);
  Context& ctx_;
  const ComputePipeline& pipeline_;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

// Per-pass GPU times from timestamp queries, in milliseconds.
class GpuTimer {
 public:
  explicit GpuTimer(Context& ctx, uint32_t maxScopes = 32);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  bool supported() const { return supported_; }
  void reset(VkCommandBuffer cmd);
  uint32_t begin(VkCommandBuffer cmd, const std::string& name);
  void end(VkCommandBuffer cmd, uint32_t scope);
  // After the command buffer completed: (name, ms) per scope, in recording order.
  std::vector<std::pair<std::string, double>> read();

 private:
  Context& ctx_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t maxScopes_;
  std::vector<std::string> names_;
  bool supported_ = false;
  uint32_t stampsPerScope_ = 2;  // begin, end; on CPU devices also a flushing stamp after each

  void stamp(VkCommandBuffer cmd, VkPipelineStageFlagBits stage, uint32_t query);
};

// Full compute->compute, compute->transfer and compute->indirect-dispatch memory barrier.
void computeBarrier(VkCommandBuffer cmd);

struct ComputePass {
  ComputePass(Context& ctx, const std::vector<uint32_t>& spirv, std::vector<BindingType> bindings,
              uint32_t pushConstantBytes, std::string name, glm::uvec3 localSize);
  // Dispatches enough groups to cover `items` threads; records timestamps if a timer is given.
  void record(VkCommandBuffer cmd, glm::uvec3 items, const void* push = nullptr, GpuTimer* timer = nullptr) const;
  // Dispatches the groups written at `offset` of `args` (a VkDispatchIndirectCommand, by an
  // earlier pass: `args` needs VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT).
  void recordIndirect(VkCommandBuffer cmd, const Buffer& args, VkDeviceSize offset, const void* push = nullptr,
                      GpuTimer* timer = nullptr) const;

  ComputePipeline pipeline;
  DescriptorSet set;
  glm::uvec3 localSize;

 private:
  void bindAll(VkCommandBuffer cmd, const void* push) const;  // pipeline, set and push constants
};

}  // namespace plume::gpu
