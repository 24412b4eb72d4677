#include "gpu/context.h"

#include "core/error.h"
#include "core/log.h"
#include "gpu/check.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>

namespace plume::gpu {
namespace {

const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower((unsigned char)c));
  return s;
}

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void* user) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    static_cast<Context*>(user)->onValidationMessage(data->pMessage);
  }
  return VK_FALSE;
}

bool layerAvailable(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const auto& l) { return std::strcmp(l.layerName, name) == 0; });
}

int typeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

VkInstance createInstance(bool validation, const std::vector<std::string>& extraExtensions = {}) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "plume";
  app.apiVersion = VK_API_VERSION_1_2;
  std::vector<const char*> layers, extensions;
  if (validation) {
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  for (const std::string& e : extraExtensions) extensions.push_back(e.c_str());
  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &app;
  ci.enabledLayerCount = uint32_t(layers.size());
  ci.ppEnabledLayerNames = layers.data();
  ci.enabledExtensionCount = uint32_t(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  VkResult r = vkCreateInstance(&ci, nullptr, &instance);
  if (r != VK_SUCCESS) {
    throw DeviceError(strf("no Vulkan instance (vkCreateInstance: %s); is a Vulkan driver installed "
                           "(mesa-vulkan-drivers for lavapipe)?", vkResultName(r)));
  }
  return instance;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  uint32_t n = 0;
  PLUME_VK(vkEnumeratePhysicalDevices(instance, &n, nullptr));
  std::vector<VkPhysicalDevice> devices(n);
  PLUME_VK(vkEnumeratePhysicalDevices(instance, &n, devices.data()));
  return devices;
}

// A queue family with compute; with a surface, one that also has graphics (UI drawing) and can
// present to it, so that one queue serves the whole frame.
int computeQueueFamily(VkPhysicalDevice d, VkSurfaceKHR surface = VK_NULL_HANDLE) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(d, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(d, &n, families.data());
  for (uint32_t i = 0; i < n; ++i) {
    if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
    if (surface) {
      VkBool32 present = VK_FALSE;
      if (vkGetPhysicalDeviceSurfaceSupportKHR(d, i, surface, &present) != VK_SUCCESS || !present) continue;
      if (!(families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT)) continue;
    }
    return int(i);
  }
  return -1;
}

bool hasDeviceExtension(VkPhysicalDevice d, const char* name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(d, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateDeviceExtensionProperties(d, nullptr, &n, exts.data());
  return std::any_of(exts.begin(), exts.end(), [&](const auto& e) { return std::strcmp(e.extensionName, name) == 0; });
}

}  // namespace

void Context::onValidationMessage(const char* message) {
  validationMessages_.fetch_add(1);
  std::fprintf(stderr, "plume: vulkan validation: %s\n", message);
}

std::vector<std::string> Context::listDevices() {
  VkInstance instance = createInstance(false);
  std::vector<std::string> names;
  for (VkPhysicalDevice d : physicalDevices(instance)) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    names.push_back(p.deviceName);
  }
  vkDestroyInstance(instance, nullptr);
  return names;
}

Context::Context(const ContextOptions& options) {
  validation_ = options.validation || envFlag("PLUME_VALIDATION");
  if (validation_ && !layerAvailable(kValidationLayer)) {
    throw DeviceError(std::string(kValidationLayer) + " requested but not installed (vulkan-validationlayers)");
  }
  instance_ = createInstance(validation_, options.instanceExtensions);
  if (validation_) {
    auto create = (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT");
    VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mi.pfnUserCallback = debugCallback;
    mi.pUserData = this;
    if (create) PLUME_VK(create(instance_, &mi, nullptr, &messenger_));
  }
  if (options.createSurface) {
    try {
      surface_ = options.createSurface(instance_);
    } catch (...) {
      release();
      throw;
    }
    if (!surface_) {
      release();
      throw DeviceError("no window surface could be created");
    }
  }

  // Choose: the named device, else the best-ranked type that has a compute queue.
  std::vector<VkPhysicalDevice> devices = physicalDevices(instance_);
  std::string available;
  int bestRank = 1 << 30;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    available += std::string(available.empty() ? "" : ", ") + p.deviceName;
    if (computeQueueFamily(d, surface_) < 0) continue;
    if (surface_ && !hasDeviceExtension(d, VK_KHR_SWAPCHAIN_EXTENSION_NAME)) continue;
    if (!options.deviceName.empty()) {
      if (lower(p.deviceName).find(lower(options.deviceName)) == std::string::npos) continue;
    }
    if (typeRank(p.deviceType) < bestRank) {
      bestRank = typeRank(p.deviceType);
      physical_ = d;
    }
  }
  if (!physical_) {
    std::string what = options.deviceName.empty() ? "no Vulkan device with a compute queue"
                                                  : "no Vulkan device matches \"" + options.deviceName + "\"";
    if (surface_) what += " that can present to the window (compute + graphics + present, VK_KHR_swapchain)";
    release();
    throw DeviceError(what + " (devices: " + (available.empty() ? "none" : available) + ")");
  }
  vkGetPhysicalDeviceProperties(physical_, &props_);
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props2.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(physical_, &props2);
  subgroupBallot_ = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
                    (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT) != 0;
  vkGetPhysicalDeviceMemoryProperties(physical_, &memProps_);
  queueFamily_ = uint32_t(computeQueueFamily(physical_, surface_));
  if (options.verbose) logInfo(strf("device: %s%s", props_.deviceName, validation_ ? " (validation on)" : ""));

  float priority = 1.0f;
  VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qi.queueFamilyIndex = queueFamily_;
  qi.queueCount = 1;
  qi.pQueuePriorities = &priority;
  VkPhysicalDeviceFeatures features{};
  VkDeviceCreateInfo di{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  di.queueCreateInfoCount = 1;
  di.pQueueCreateInfos = &qi;
  di.pEnabledFeatures = &features;
  const char* swapchainExt = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
  if (surface_) {
    di.enabledExtensionCount = 1;
    di.ppEnabledExtensionNames = &swapchainExt;
  }
  PLUME_VK(vkCreateDevice(physical_, &di, nullptr, &device_));
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pi.queueFamilyIndex = queueFamily_;
  PLUME_VK(vkCreateCommandPool(device_, &pi, nullptr, &pool_));
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  PLUME_VK(vkCreateFence(device_, &fi, nullptr, &fence_));
}

Context::~Context() { release(); }

void Context::release() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (surface_) {
    vkDestroySurfaceKHR(instance_, surface_, nullptr);
    surface_ = VK_NULL_HANDLE;
  }
  if (messenger_) {
    auto destroy = (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT");
    if (destroy) destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
  }
  if (instance_) {
    vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
  }
}

uint32_t Context::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                                 VkMemoryPropertyFlags preferred) const {
  for (int pass = 0; pass < 2; ++pass) {
    VkMemoryPropertyFlags want = pass == 0 ? (required | preferred) : required;
    for (uint32_t i = 0; i < memProps_.memoryTypeCount; ++i) {
      if ((typeBits & (1u << i)) && (memProps_.memoryTypes[i].propertyFlags & want) == want) return i;
    }
  }
  throw DeviceError(strf("%s: no memory type with flags 0x%x", props_.deviceName, unsigned(required)));
}

VkMemoryPropertyFlags Context::memoryTypeFlags(uint32_t type) const {
  return memProps_.memoryTypes[type].propertyFlags;
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  PLUME_VK(vkAllocateCommandBuffers(device_, &ai, &cmd));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  PLUME_VK(vkBeginCommandBuffer(cmd, &bi));
  record(cmd);
  PLUME_VK(vkEndCommandBuffer(cmd));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  PLUME_VK(vkResetFences(device_, 1, &fence_));
  PLUME_VK(vkQueueSubmit(queue_, 1, &si, fence_));
  PLUME_VK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
  vkFreeCommandBuffers(device_, pool_, 1, &cmd);
}

const char* vkResultName(VkResult r) {
  switch (r) {
#define PLUME_CASE(x) case x: return #x;
    PLUME_CASE(VK_SUCCESS) PLUME_CASE(VK_NOT_READY) PLUME_CASE(VK_TIMEOUT) PLUME_CASE(VK_INCOMPLETE)
    PLUME_CASE(VK_ERROR_OUT_OF_HOST_MEMORY) PLUME_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    PLUME_CASE(VK_ERROR_INITIALIZATION_FAILED) PLUME_CASE(VK_ERROR_DEVICE_LOST)
    PLUME_CASE(VK_ERROR_MEMORY_MAP_FAILED) PLUME_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    PLUME_CASE(VK_ERROR_EXTENSION_NOT_PRESENT) PLUME_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    PLUME_CASE(VK_ERROR_INCOMPATIBLE_DRIVER) PLUME_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    PLUME_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED) PLUME_CASE(VK_ERROR_FRAGMENTED_POOL)
    PLUME_CASE(VK_ERROR_OUT_OF_POOL_MEMORY) PLUME_CASE(VK_ERROR_SURFACE_LOST_KHR)
    PLUME_CASE(VK_SUBOPTIMAL_KHR) PLUME_CASE(VK_ERROR_OUT_OF_DATE_KHR)
#undef PLUME_CASE
    default: return "VK_ERROR_UNKNOWN";
  }
}

void throwVkError(VkResult r, const char* expr, const char* file, int line) {
  throw DeviceError(strf("%s failed: %s (%s:%d)", expr, vkResultName(r), file, line));
}

}  // namespace plume::gpu
