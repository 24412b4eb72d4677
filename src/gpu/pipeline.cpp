#include "gpu/pipeline.h"

#include "core/error.h"
#include "core/log.h"
#include "gpu/check.h"

#include <algorithm>

namespace plume::gpu {
namespace {

VkDescriptorType descriptorType(BindingType t) {
  switch (t) {
    case BindingType::StorageBuffer: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    case BindingType::UniformBuffer: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    case BindingType::SampledImage: return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    case BindingType::TexelBuffer: return VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    case BindingType::StorageTexelBuffer: return VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
  }
  return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

}  // namespace

ComputePipeline::ComputePipeline(Context& ctx, const std::vector<uint32_t>& spirv,
                                 std::vector<BindingType> bindings, uint32_t pushConstantBytes,
                                 std::string name)
    : ctx_(ctx), bindings_(std::move(bindings)), pushBytes_(pushConstantBytes), name_(std::move(name)) {
  if (pushBytes_ > ctx.limits().maxPushConstantsSize) {
    throw DeviceError(strf("%s: pass %s needs %u bytes of push constants; the device allows %u",
                           ctx.deviceName().c_str(), name_.c_str(), pushBytes_, ctx.limits().maxPushConstantsSize));
  }
  VkShaderModuleCreateInfo mi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  mi.codeSize = spirv.size() * 4;
  mi.pCode = spirv.data();
  PLUME_VK(vkCreateShaderModule(ctx.device(), &mi, nullptr, &module_));

  std::vector<VkDescriptorSetLayoutBinding> lb;
  for (uint32_t i = 0; i < bindings_.size(); ++i) {
    lb.push_back({i, descriptorType(bindings_[i]), 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
  }
  VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  li.bindingCount = uint32_t(lb.size());
  li.pBindings = lb.data();
  PLUME_VK(vkCreateDescriptorSetLayout(ctx.device(), &li, nullptr, &setLayout_));

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes_};
  VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &setLayout_;
  pli.pushConstantRangeCount = pushBytes_ ? 1 : 0;
  pli.pPushConstantRanges = pushBytes_ ? &range : nullptr;
  PLUME_VK(vkCreatePipelineLayout(ctx.device(), &pli, nullptr, &layout_));

  VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module_;
  ci.stage.pName = "main";
  ci.layout = layout_;
  PLUME_VK(vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline_));
}

ComputePipeline::~ComputePipeline() {
  VkDevice d = ctx_.device();
  if (pipeline_) vkDestroyPipeline(d, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(d, layout_, nullptr);
  if (setLayout_) vkDestroyDescriptorSetLayout(d, setLayout_, nullptr);
  if (module_) vkDestroyShaderModule(d, module_, nullptr);
}

DescriptorSet::DescriptorSet(Context& ctx, const ComputePipeline& pipeline) : ctx_(ctx), pipeline_(pipeline) {
  std::vector<VkDescriptorPoolSize> sizes;
  for (BindingType t : pipeline.bindings()) sizes.push_back({descriptorType(t), 1});
  VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pi.maxSets = 1;
  pi.poolSizeCount = uint32_t(sizes.size());
  pi.pPoolSizes = sizes.data();
  if (sizes.empty()) {
    static const VkDescriptorPoolSize dummy{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
    pi.poolSizeCount = 1;
    pi.pPoolSizes = &dummy;
  }
  PLUME_VK(vkCreateDescriptorPool(ctx.device(), &pi, nullptr, &pool_));
  VkDescriptorSetLayout layout = pipeline.setLayout();
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool_;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &layout;
  PLUME_VK(vkAllocateDescriptorSets(ctx.device(), &ai, &set_));
}

DescriptorSet::~DescriptorSet() {
  if (pool_) vkDestroyDescriptorPool(ctx_.device(), pool_, nullptr);
}

// One descriptor at `binding`, whose declared type must be one of `allowed` (one info is given).
void DescriptorSet::write(uint32_t binding, std::initializer_list<BindingType> allowed,
                          const VkDescriptorImageInfo* image, const VkDescriptorBufferInfo* buffer,
                          const VkBufferView* texels) {
  PLUME_CHECK(binding < pipeline_.bindings().size());
  const BindingType type = pipeline_.bindings()[binding];
  PLUME_CHECK(std::find(allowed.begin(), allowed.end(), type) != allowed.end());
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set_;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = descriptorType(type);
  w.pImageInfo = image;
  w.pBufferInfo = buffer;
  w.pTexelBufferView = texels;
  vkUpdateDescriptorSets(ctx_.device(), 1, &w, 0, nullptr);
}

void DescriptorSet::bind(uint32_t binding, const Buffer& buffer) {
  const VkDescriptorBufferInfo bi{buffer.handle(), 0, VK_WHOLE_SIZE};
  write(binding, {BindingType::StorageBuffer, BindingType::UniformBuffer}, nullptr, &bi, nullptr);
}

void DescriptorSet::bind(uint32_t binding, const Image3D& image) {
  const VkDescriptorImageInfo ii{image.sampler(), image.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  write(binding, {BindingType::SampledImage}, &ii, nullptr, nullptr);
}

void DescriptorSet::bind(uint32_t binding, const TexelBuffer& buffer) {
  const VkBufferView view = buffer.view();
  write(binding, {BindingType::TexelBuffer, BindingType::StorageTexelBuffer}, nullptr, nullptr, &view);
}

GpuTimer::GpuTimer(Context& ctx, uint32_t maxScopes) : ctx_(ctx), maxScopes_(maxScopes) {
  supported_ = ctx.limits().timestampComputeAndGraphics && ctx.limits().timestampPeriod > 0;
  if (!supported_) return;
  stampsPerScope_ = ctx.isCpuDevice() ? 4 : 2;
  VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
  qi.queryCount = stampsPerScope_ * maxScopes;
  PLUME_VK(vkCreateQueryPool(ctx.device(), &qi, nullptr, &pool_));
}

GpuTimer::~GpuTimer() {
  if (pool_) vkDestroyQueryPool(ctx_.device(), pool_, nullptr);
}

void GpuTimer::reset(VkCommandBuffer cmd) {
  names_.clear();
  if (supported_) vkCmdResetQueryPool(cmd, pool_, 0, stampsPerScope_ * maxScopes_);
}

// On a CPU device (lavapipe) a timestamp is taken when llvmpipe's rasterizer runs its bins if a
// framebuffer has ever been bound on the queue (the viewer's panel), i.e. at the next flush, long
// after a compute pass that ran in between: every pass read ~0.03 ms in the viewer. A second
// timestamp right after, of a stage that makes lavapipe flush first, takes the first one's value
// there and then; the second one's value is never read.
void GpuTimer::stamp(VkCommandBuffer cmd, VkPipelineStageFlagBits stage, uint32_t query) {
  vkCmdWriteTimestamp(cmd, stage, pool_, query);
  if (stampsPerScope_ == 4) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, query + 2);
}

uint32_t GpuTimer::begin(VkCommandBuffer cmd, const std::string& name) {
  PLUME_CHECK_MSG(names_.size() < maxScopes_, "too many timer scopes");
  uint32_t scope = uint32_t(names_.size());
  names_.push_back(name);
  if (supported_) stamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, stampsPerScope_ * scope);
  return scope;
}

void GpuTimer::end(VkCommandBuffer cmd, uint32_t scope) {
  if (supported_) stamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, stampsPerScope_ * scope + 1);
}

std::vector<std::pair<std::string, double>> GpuTimer::read() {
  std::vector<std::pair<std::string, double>> out;
  if (!supported_ || names_.empty()) return out;
  std::vector<uint64_t> ticks(stampsPerScope_ * names_.size());
  PLUME_VK(vkGetQueryPoolResults(ctx_.device(), pool_, 0, uint32_t(ticks.size()), ticks.size() * 8,
                                 ticks.data(), 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const double msPerTick = ctx_.limits().timestampPeriod * 1e-6;
  for (size_t i = 0; i < names_.size(); ++i) {
    out.emplace_back(names_[i], double(ticks[stampsPerScope_ * i + 1] - ticks[stampsPerScope_ * i]) * msPerTick);
  }
  return out;
}

std::vector<BindingType> bindingTable(uint32_t count, const BindingTypes& others) {
  std::vector<BindingType> table(count, BindingType::StorageBuffer);
  for (const auto& [binding, type] : others) {
    PLUME_CHECK(binding < count);
    table[binding] = type;
  }
  return table;
}

void computeBarrier(VkCommandBuffer cmd) {
  VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                    VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                           VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                       0, 1, &b, 0, nullptr, 0, nullptr);
}

ComputePass::ComputePass(Context& ctx, const std::vector<uint32_t>& spirv, std::vector<BindingType> bindings,
                         uint32_t pushConstantBytes, std::string name, glm::uvec3 local)
    : pipeline(ctx, spirv, std::move(bindings), pushConstantBytes, std::move(name)), set(ctx, pipeline),
      localSize(local) {}

void ComputePass::bindAll(VkCommandBuffer cmd, const void* push) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline());
  VkDescriptorSet s = set.handle();
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.layout(), 0, 1, &s, 0, nullptr);
  if (pipeline.pushConstantBytes() > 0) {
    PLUME_CHECK(push != nullptr);
    vkCmdPushConstants(cmd, pipeline.layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, pipeline.pushConstantBytes(), push);
  }
}

void ComputePass::record(VkCommandBuffer cmd, glm::uvec3 items, const void* push, GpuTimer* timer) const {
  uint32_t scope = timer ? timer->begin(cmd, pipeline.name()) : 0;
  bindAll(cmd, push);
  glm::uvec3 groups = (items + localSize - glm::uvec3(1)) / localSize;
  vkCmdDispatch(cmd, groups.x, groups.y, groups.z);
  if (timer) timer->end(cmd, scope);
}

void ComputePass::recordIndirect(VkCommandBuffer cmd, const Buffer& args, VkDeviceSize offset, const void* push,
                                 GpuTimer* timer) const {
  uint32_t scope = timer ? timer->begin(cmd, pipeline.name()) : 0;
  bindAll(cmd, push);
  vkCmdDispatchIndirect(cmd, args.handle(), offset);
  if (timer) timer->end(cmd, scope);
}

}  // namespace plume::gpu
