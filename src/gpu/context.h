// The Vulkan instance, the chosen physical device and a logical device with one compute queue.
// Device choice: a discrete GPU, then an integrated one, then anything else (lavapipe);
// `deviceName` (a case-insensitive substring) forces one. Validation layers are enabled when
// asked for or when PLUME_VALIDATION=1; every validation message is printed and counted, and
// the tests fail on any.
//
// Presentation (the viewer) is opt-in through ContextOptions: extra instance extensions (those a
// window system needs) and a callback that creates a VkSurfaceKHR once the instance exists. The
// device is then one whose queue family supports compute, graphics and present to that surface,
// with VK_KHR_swapchain enabled. The default stays headless and compute-only.
#pragma once

#ifdef PLUME_NO_GPU
#error "the CPU reference never includes gpu/: it is independent of what it checks (CMakeLists.txt)"
#endif

#include <vulkan/vulkan.h>

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace plume::gpu {

struct ContextOptions {
  std::string deviceName;  // empty: choose automatically
  bool validation = false;
  bool verbose = true;     // print the chosen device
  // Presentation, all optional: instance extensions (e.g. glfwGetRequiredInstanceExtensions) and
  // a surface factory called with the new instance. The Context owns and destroys the surface.
  std::vector<std::string> instanceExtensions;
  std::function<VkSurfaceKHR(VkInstance)> createSurface;
};

class Context {
 public:
  explicit Context(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkSurfaceKHR surface() const { return surface_; }  // VK_NULL_HANDLE when headless
  bool presents() const { return surface_ != VK_NULL_HANDLE; }
  VkDevice device() const { return device_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queueFamily_; }
  VkCommandPool commandPool() const { return pool_; }
  const VkPhysicalDeviceProperties& properties() const { return props_; }
  const VkPhysicalDeviceLimits& limits() const { return props_.limits; }
  std::string deviceName() const { return props_.deviceName; }
  bool isCpuDevice() const { return props_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
  // Whether compute shaders may use subgroup ballots (GL_KHR_shader_subgroup_ballot).
  bool subgroupBallot() const { return subgroupBallot_; }
  bool validationEnabled() const { return validation_; }
  uint64_t validationMessages() const { return validationMessages_.load(); }
  // The texture unit's trilinear weight error on this device, measured once by a higher layer
  // (render/filter_probe.h) and kept here for the context's life; nullopt until then.
  std::optional<double> filterWeightError() const { return filterWeightError_; }
  void setFilterWeightError(double e) { filterWeightError_ = e; }

  // A memory type allowed by typeBits with all of `required` (and `preferred` if possible).
  uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                          VkMemoryPropertyFlags preferred = 0) const;
  VkMemoryPropertyFlags memoryTypeFlags(uint32_t type) const;

  // Records into a fresh primary command buffer, submits it and waits.
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record);

  static std::vector<std::string> listDevices();

  // Internal: called by the debug messenger.
  void onValidationMessage(const char* message);

 private:
  void release();

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties props_{};
  VkPhysicalDeviceMemoryProperties memProps_{};
  bool validation_ = false;
  bool subgroupBallot_ = false;
  std::atomic<uint64_t> validationMessages_{0};
  std::optional<double> filterWeightError_;
};

}  // namespace plume::gpu
