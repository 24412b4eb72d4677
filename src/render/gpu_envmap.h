// The scene's environment map for the GPU estimators (DESIGN §2; shaders/shared/envmap.h): the
// texels (radiance times the light's `scale`) and the sampling CDFs built on the host, uploaded
// as one texel buffer of 32-bit words (the GpuEnvMap header, then the data) bound at
// BIND_ENV_MAP. A scene without a map gets a one-texel black placeholder (its variants never read
// it).
#pragma once

#include "gpu/pipeline.h"
#include "gpu/resources.h"
#include "io/environment_map.h"
#include "scene/scene.h"
#include "shaders/shared/gpu_types.h"

#include <glm/mat3x3.hpp>

#include <vector>

namespace plume {

// R = R_y(-rotateYDeg) M, M the minimal rotation taking unit `up` to +Y (180 degrees about X
// when up = -Y): world direction d_w reads the map at R d_w (DESIGN §2).
glm::dmat3 envMapWorldToLocal(glm::vec3 up, float rotateYDeg);

// What the buffer holds: the header and the float data of shared/envmap.h.
struct EnvMapData {
  shared::GpuEnvMap header{};
  std::vector<float> data;
  glm::vec3 meanRadiance{0};  // mean over the sphere (solid angle), for ReSTIR's light choice
};
EnvMapData buildEnvMapData(const EnvironmentMapImage& image, float scale, glm::vec3 up, float rotateYDeg);

// Device bytes per texel (bounds the rest: the CDFs' 2H + 1 floats) and the largest map a
// device's storage buffers can hold.
constexpr uint64_t kEnvMapBytesPerTexel = 20;
EnvironmentMapLimit envMapLimit(const VkPhysicalDeviceLimits& limits);

class GpuEnvironmentMap {
 public:
  // Loads the scene's map, if any (InputError naming lights[i].map on bad input).
  GpuEnvironmentMap(gpu::Context& ctx, const Scene& scene);
  void bind(gpu::DescriptorSet& set) const;
  bool present() const { return present_; }
  glm::vec3 meanRadiance() const { return meanRadiance_; }

 private:
  gpu::TexelBuffer buffer_;
  bool present_ = false;
  glm::vec3 meanRadiance_{0};
};

}  // namespace plume
