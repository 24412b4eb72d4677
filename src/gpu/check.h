// Every vk* call is checked: PLUME_VK(expr) throws DeviceError naming the expression, the
// VkResult, the file and the line.
#pragma once

#include <vulkan/vulkan.h>

namespace plume::gpu {

const char* vkResultName(VkResult r);
void throwVkError(VkResult r, const char* expr, const char* file, int line);

}  // namespace plume::gpu

#define PLUME_VK(expr)                                                              \
  do {                                                                              \
    VkResult plume_vk_result_ = (expr);                                             \
    if (plume_vk_result_ != VK_SUCCESS)                                             \
      ::plume::gpu::throwVkError(plume_vk_result_, #expr, __FILE__, __LINE__);      \
  } while (0)
